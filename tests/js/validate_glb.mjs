// The .glb files skinmesh writes pass the Khronos glTF validator with no
// error and no warning: a mesh (`skinmesh mesh -o X.glb`) and a morph
// (`skinmesh morph --format glb`, every frame a node shown by a stepped
// animation). Also checks what the files hold against what skinmesh says
// it wrote: the mesh's vertex count, one node and one animation channel per
// frame. Usage: node validate_glb.mjs SKINMESH DATA_DIR
import { execFileSync } from 'node:child_process';
import { mkdtempSync, readFileSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import validator from 'gltf-validator';

const [skinmesh, data] = process.argv.slice(2);
if (!skinmesh || !data) throw new Error('usage: node validate_glb.mjs SKINMESH DATA_DIR');
const work = mkdtempSync(join(tmpdir(), 'skinmesh-glb-'));
let failures = 0;
const check = (ok, what) => {
  console.log(`${ok ? 'ok  ' : 'FAIL'} ${what}`);
  if (!ok) failures += 1;
};

// The GLB's JSON chunk, read by its header (magic, version, length).
function gltfJson(bytes) {
  const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  if (view.getUint32(0, true) !== 0x46546c67) throw new Error('not a GLB');
  const length = view.getUint32(12, true);
  return JSON.parse(new TextDecoder().decode(bytes.subarray(20, 20 + length)));
}

async function validate(path) {
  const bytes = new Uint8Array(readFileSync(path));
  const report = await validator.validateBytes(bytes, { uri: path, maxIssues: 50 });
  const { numErrors, numWarnings, messages } = report.issues;
  for (const m of messages.filter((m) => m.severity <= 1)) console.log(`  ${m.code} ${m.pointer ?? ''}: ${m.message}`);
  check(numErrors === 0 && numWarnings === 0, `${path}: ${numErrors} errors, ${numWarnings} warnings`);
  return gltfJson(bytes);
}

try {
  const run = (args) => execFileSync(skinmesh, ['--quiet', ...args], { stdio: ['ignore', 'inherit', 'inherit'] });
  const mesh = join(work, 'pept.glb');
  run(['mesh', join(data, 'pept.pdb'), '-o', mesh, '--colour', 'residue', '--report', join(work, 'pept.json')]);
  const doc = await validate(mesh);
  const vertices = JSON.parse(readFileSync(join(work, 'pept.json'), 'utf8')).quality.vertices;
  const primitive = doc.meshes[0].primitives[0];
  check(doc.accessors[primitive.attributes.POSITION].count === vertices,
        `mesh: POSITION holds the report's ${vertices} vertices`);
  check('COLOR_0' in primitive.attributes && 'NORMAL' in primitive.attributes, 'mesh: colours and normals');

  const morph = join(work, 'morph');
  const pdb = join(data, '2k39_3models.pdb');
  run(['morph', pdb, pdb, '--source-model', '1', '--target-model', '2', '--frames', '3', '--format', 'glb,ply',
       '--colour', 'element', '-o', morph]);
  const frames = readFileSync(join(morph, 'frames.jsonl'), 'utf8').trim().split('\n').map((l) => JSON.parse(l));
  const animated = await validate(join(morph, 'frames.glb'));
  check(animated.nodes.length === frames.length && animated.scenes[0].nodes.length === frames.length,
        `morph: ${frames.length} frames, one node each`);
  const channels = animated.animations[0].channels;
  check(channels.length === frames.length && channels.every((c) => c.target.path === 'scale'),
        'morph: one scale channel per node');
  check(animated.animations[0].samplers.every((s) => s.interpolation === 'STEP'), 'morph: stepped visibility');
  check(frames.every((f, k) => animated.accessors[animated.meshes[animated.nodes[k].mesh].primitives[0].attributes.POSITION].count === f.vertices),
        'morph: each node holds its frame\'s vertices');
} finally {
  rmSync(work, { recursive: true, force: true });
}
if (failures > 0) {
  console.log(`${failures} check(s) failed`);
  process.exit(1);
}
