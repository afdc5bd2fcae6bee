// The viewer's tests in headless Chromium (Debian's /usr/bin/chromium driven
// by playwright-core; WebGL2 on SwiftShader, no GPU):
//   node viewer.test.mjs FIXTURES_DIR CASE
// FIXTURES_DIR is what make_fixtures.sh made. A missing browser, node module
// or fixture is a failure, never a skip.
import assert from 'node:assert/strict';
import fs from 'node:fs';
import http from 'node:http';
import os from 'node:os';
import path from 'node:path';
import { createRequire } from 'node:module';
import { pathToFileURL } from 'node:url';
import { readPly } from './ply.mjs';

const require = createRequire(import.meta.url);
const { chromium } = require('playwright-core');
const [fixtures, testCase, shotDir] = process.argv.slice(2);
const WIDTH = 800, HEIGHT = 600;

async function withBrowser(body) {
  const profile = fs.mkdtempSync(path.join(os.tmpdir(), 'skinmesh-chromium-'));
  const context = await chromium.launchPersistentContext(profile, {
    executablePath: '/usr/bin/chromium',
    headless: true,
    viewport: { width: WIDTH, height: HEIGHT },
    deviceScaleFactor: 1,
    args: ['--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run', '--disable-background-networking',
           '--disable-component-update', '--disable-sync', '--enable-unsafe-swiftshader'],
  });
  try {
    return await body(context);
  } finally {
    await context.close();
    fs.rmSync(profile, { recursive: true, force: true });
  }
}

// Opens a page with every request but the page's own refused and recorded.
async function openOffline(context, file, fragment = '') {
  const page = await context.newPage();
  const url = pathToFileURL(path.join(fixtures, file)).href;
  const requests = [];
  await context.setOffline(true);
  await context.route('**/*', (route) => {
    if (route.request().url().split('#')[0] === url) return route.continue();
    requests.push(route.request().url());
    return route.abort();
  });
  await page.goto(`${url}${fragment ? `#${fragment}` : ''}`);
  await waitReady(page);
  if (process.env.SKINMESH_TEST_TIMES) console.log(`${file} ready at ${Date.now() - started} ms`);
  return { page, requests };
}

async function waitReady(page) {
  await page.waitForFunction(() => document.body.dataset.ready === '1' || document.body.dataset.error, null, { timeout: 30000 });
  const error = await page.evaluate(() => document.body.dataset.error);
  assert.equal(error, undefined, `the viewer failed: ${error}`);
}

// The canvas's pixels, read back in the page (the context keeps its drawing buffer).
async function pixels(page) {
  const text = await page.evaluate(() => {
    window.skinmeshViewer.drawNow();
    const c = document.getElementById('view');
    const copy = document.createElement('canvas');
    copy.width = c.width; copy.height = c.height;
    const g = copy.getContext('2d');
    g.drawImage(c, 0, 0);
    const data = g.getImageData(0, 0, c.width, c.height).data;
    let binary = '';
    for (let i = 0; i < data.length; i += 32768) binary += String.fromCharCode(...data.subarray(i, i + 32768));
    return btoa(binary);
  });
  return new Uint8Array(Buffer.from(text, 'base64'));
}

function covered(px) {  // pixels unlike the background (its colour is the top-left corner's)
  let n = 0;
  for (let i = 0; i < px.length; i += 4)
    if (Math.abs(px[i] - px[0]) + Math.abs(px[i + 1] - px[1]) + Math.abs(px[i + 2] - px[2]) > 24) ++n;
  return n;
}

function differing(a, b) {
  let n = 0;
  for (let i = 0; i < a.length; i += 4)
    if (Math.abs(a[i] - b[i]) + Math.abs(a[i + 1] - b[i + 1]) + Math.abs(a[i + 2] - b[i + 2]) > 24) ++n;
  return n;
}

async function setFragment(page, fragment) {
  await page.evaluate((f) => { location.hash = f; }, fragment);
  await page.waitForFunction((f) => {
    const want = new URLSearchParams(f), got = window.skinmeshViewer.state();
    return [...want.keys()].every((k) => String(got[k]) === want.get(k) || Number(got[k]) === Number(want.get(k)));
  }, fragment);
}

async function shot(page, name) {
  if (shotDir) await page.screenshot({ path: path.join(shotDir, name) });
}

function frameTimes() {
  return fs.readFileSync(path.join(fixtures, 'morph', 'frames.jsonl'), 'utf8').trim().split('\n').map((l) => JSON.parse(l));
}

// Whether every vertex of a morph frame has source and target atoms of the same residue.
function sameResidues(frameFile) {
  const ply = readPly(path.join(fixtures, 'morph', frameFile.replace(/\.\w+$/, '.ply')));
  const residue = (side) => fs.readFileSync(path.join(fixtures, 'morph', `${side}_atoms.tsv`), 'utf8').trim().split('\n').slice(1)
    .map((l) => l.split('\t').slice(1, 5).join(':'));
  const source = residue('source'), target = residue('target');
  const has = (side, i) => ply.properties[`${side}_atom`][i] >= 0 && (ply.properties[`has_${side}_atom`]?.[i] ?? 1) !== 0;
  return ply.properties.source_atom.every((a, i) => has('source', i) && has('target', i) &&
                                                   source[a] === target[ply.properties.target_atom[i]]);
}

const cases = {
  // The page loads with no request beyond itself, and draws the molecule.
  async offline(context) {
    for (const file of ['1ubi.html', 'morph.html']) {
      const { page, requests } = await openOffline(context, file);
      assert.deepEqual(requests, [], `${file} asked the network for ${requests}`);
      const n = covered(await pixels(page));
      assert.ok(n > 0.05 * WIDTH * HEIGHT && n < 0.9 * WIDTH * HEIGHT, `${file}: ${n} pixels drawn`);
      await shot(page, file.replace('.html', '.png'));
      await page.close();
    }
  },

  // The morph at its two ends looks different, and the fragment sets t.
  async ends(context) {
    const { page } = await openOffline(context, 'morph.html', 't=0&colour=patch');
    const start = await pixels(page);
    await setFragment(page, 't=1&colour=patch');
    const end = await pixels(page);
    const n = differing(start, end);
    assert.ok(n > 0.01 * WIDTH * HEIGHT, `t = 0 and t = 1 differ in ${n} pixels only`);
    // A trajectory's t runs from 0 to its last model's index.
    const traj = (await openOffline(context, 'traj.html', 't=1.5&colour=patch')).page;
    assert.deepEqual((await traj.evaluate(() => window.skinmeshViewer.frames())).map((f) => f.t), [0, 0.5, 1, 1.5, 2]);
    assert.equal((await traj.evaluate(() => window.skinmeshViewer.state())).t, 1.5);
    const between = await traj.evaluate(() => window.skinmeshViewer.positionsAt(1.25));
    assert.deepEqual([between.from.file, between.to.file, between.s], ['frame_2.ply', 'frame_3.ply', 0.5]);
    const middle = await pixels(traj);
    await setFragment(traj, 't=2&colour=patch');
    assert.ok(differing(middle, await pixels(traj)) > 0.01 * WIDTH * HEIGHT, 'the trajectory does not move from t = 1.5 to 2');
  },

  // Between two frames, every vertex whose id both hold is at its place
  // interpolated by id, as computed here from the frame files themselves.
  async interpolation(context) {
    const frames = frameTimes();
    const k = 1, s = 0.37;
    const t = frames[k].t + s * (frames[k + 1].t - frames[k].t);
    const { page } = await openOffline(context, 'morph.html', `t=${t}&colour=age`);
    const shown = await page.evaluate((tt) => window.skinmeshViewer.positionsAt(tt), t);
    const a = readPly(path.join(fixtures, 'morph', frames[k].file.replace(/\.\w+$/, '.ply')));
    const b = readPly(path.join(fixtures, 'morph', frames[k + 1].file.replace(/\.\w+$/, '.ply')));
    const inB = new Map(Array.from(b.properties.id, (id, j) => [id, j]));
    assert.ok(Math.abs(shown.s - s) < 1e-6, `share ${shown.s}, expected ${s}`);
    assert.deepEqual(shown.from.ids, Array.from(a.properties.id));
    let survivors = 0, moved = 0, worst = 0;
    for (let i = 0; i < a.properties.id.length; ++i) {
      const j = inB.get(a.properties.id[i]);
      for (let c = 0; c < 3; ++c) {
        const p = a.positions[3 * i + c], q = j === undefined ? p : b.positions[3 * j + c];
        worst = Math.max(worst, Math.abs(shown.from.positions[3 * i + c] - (p + s * (q - p))));
      }
      if (j === undefined) continue;
      ++survivors;
      if (Math.hypot(...[0, 1, 2].map((c) => b.positions[3 * j + c] - a.positions[3 * i + c])) > 0.05) ++moved;
    }
    assert.ok(worst < 1e-3, `a vertex is ${worst} A from its interpolated place`);
    assert.ok(survivors > 0.5 * a.properties.id.length, `${survivors} survivors only`);
    assert.ok(moved > 0.1 * survivors, `${moved} of ${survivors} survivors move: the check would be empty`);
    // The picture between the frames is neither frame's.
    const between = await pixels(page);
    await setFragment(page, `t=${frames[k].t}&colour=age`);
    const before = await pixels(page);
    await setFragment(page, `t=${frames[k + 1].t}&colour=age`);
    const after = await pixels(page);
    assert.ok(differing(between, before) > 500 && differing(between, after) > 500, 'the picture between frames is one of them');
  },

  // Every colour mode gives its own picture, on the mesh and on the morph.
  async colours(context) {
    for (const [file, expected] of [['1ubi.html', ['chain', 'residue', 'element', 'atom', 'patch', 'quality']],
                                    ['morph.html', ['source-residue', 'target-residue', 'age', 'quality', 'patch']]]) {
      const { page } = await openOffline(context, file);
      const modes = await page.evaluate(() => window.skinmeshViewer.colourModes());
      for (const m of expected) assert.ok(modes.includes(m), `${file} lacks colour ${m} (has ${modes})`);
      const pictures = [];
      for (const m of modes) {
        await setFragment(page, file === 'morph.html' ? `t=0.5&colour=${m}` : `colour=${m}`);
        pictures.push([m, await pixels(page)]);
        if (file === '1ubi.html') await shot(page, `1ubi-${m}.png`);
      }
      for (let i = 0; i < pictures.length; ++i)
        for (let j = i + 1; j < pictures.length; ++j) {
          const n = differing(pictures[i][1], pictures[j][1]);
          if (pictures[i][0] === 'source-residue' && pictures[j][0] === 'target-residue') {
            // A matched morph pairs each atom with itself: the two agree exactly when every vertex's two atoms are of one residue.
            const same = sameResidues(frameTimes().find((f) => f.t === 0.5).file);
            assert.ok(same ? n < 50 : n > 2000, `source and target residues: ${n} pixels differ, the residues ${same ? 'agree' : 'differ'}`);
            continue;
          }
          assert.ok(n > 2000, `${file}: colour ${pictures[i][0]} and ${pictures[j][0]} differ in ${n} pixels`);
        }
      await page.close();
    }
  },

  // A click names the vertex under it and its atom as the mesh file does,
  // with that atom's row of the table.
  async picking(context) {
    const { page } = await openOffline(context, '1ubi.html', 'colour=residue&yaw=30&pitch=-20');
    const ply = readPly(path.join(fixtures, '1ubi.ply'));
    const table = fs.readFileSync(path.join(fixtures, '1ubi.atoms.tsv'), 'utf8').trim().split('\n').map((l) => l.split('\t'));
    // Three pixels the molecule covers, right of the panel.
    const px = await pixels(page), on = [];
    for (let i = 0; i < px.length; i += 4)
      if ((i / 4) % WIDTH > 340 && Math.abs(px[i] - px[0]) + Math.abs(px[i + 1] - px[1]) + Math.abs(px[i + 2] - px[2]) > 24)
        on.push([(i / 4) % WIDTH, Math.floor(i / 4 / WIDTH)]);
    assert.ok(on.length > 10000, `${on.length} pixels drawn`);
    let checked = 0;
    for (const [x, y] of [on[Math.floor(on.length / 4)], on[Math.floor(on.length / 2)], on[Math.floor(3 * on.length / 4)]]) {
      await page.mouse.click(x, y);
      const p = await page.evaluate(() => window.skinmeshViewer.lastPick);
      assert.ok(p, `nothing picked at ${x}, ${y}`);
      for (let c = 0; c < 3; ++c) assert.ok(Math.abs(p.position[c] - ply.positions[3 * p.vertex + c]) < 1e-3);
      assert.equal(p.atoms.mesh.index, ply.properties.atom[p.vertex]);
      const row = table[1 + p.atoms.mesh.index];
      assert.equal(p.atoms.mesh.atom_name, row[5]);
      assert.equal(p.atoms.mesh.residue_name, row[4]);
      assert.equal(String(p.atoms.mesh.residue_number), row[2]);
      assert.equal(p.atoms.mesh.chain, row[1]);
      const text = await page.textContent('#pick');
      assert.ok(text.includes(`${row[5]} of ${row[4]} ${row[2]}`), `the panel says ${text}`);
      ++checked;
    }
    await page.mouse.click(5, HEIGHT - 5);  // the background
    assert.equal(await page.evaluate(() => window.skinmeshViewer.lastPick), null);
    assert.equal(checked, 3);
  },

  // Without an atom table the page works with the colours that need none and says so.
  async notable(context) {
    const { page } = await openOffline(context, 'plain/1ubi.html', 'colour=residue');
    const modes = await page.evaluate(() => window.skinmeshViewer.colourModes());
    assert.deepEqual(modes.sort(), ['atom', 'patch', 'quality']);
    assert.equal((await page.evaluate(() => window.skinmeshViewer.state())).colour, 'patch');
    assert.match(await page.textContent('#note'), /No atom table/);
    assert.ok(covered(await pixels(page)) > 0.05 * WIDTH * HEIGHT);
  },

  // Turning the view by the mouse writes the fragment; the fragment read back gives the same picture.
  async fragment(context) {
    const { page } = await openOffline(context, 'morph.html', 't=0.25&colour=quality&yaw=10&pitch=0');
    await page.mouse.move(400, 300);
    await page.mouse.down();
    await page.mouse.move(500, 250, { steps: 5 });
    await page.mouse.up();
    await page.waitForFunction(() => location.hash.includes('yaw=50'));
    const hash = await page.evaluate(() => location.hash);
    assert.match(hash, /t=0\.25/);
    assert.match(hash, /pitch=-20/);
    const turned = await pixels(page);
    const again = await context.newPage();
    await again.goto(`${pathToFileURL(path.join(fixtures, 'morph.html')).href}${hash}`);
    await waitReady(again);
    assert.ok(differing(turned, await pixels(again)) < 50, 'the shared fragment shows another picture');
    // Playing moves t on.
    await setFragment(again, 't=0&play=1&speed=10');
    await again.waitForFunction(() => window.skinmeshViewer.state().t > 0.2);
  },

  // --no-embed: the page in the morph's directory reads the frames by relative address from a local server.
  async noembed(context) {
    const root = path.join(fixtures, 'morph');
    const server = http.createServer((req, res) => {
      const file = path.join(root, decodeURIComponent(new URL(req.url, 'http://x').pathname));
      if (!file.startsWith(root) || !fs.existsSync(file)) { res.writeHead(404).end(); return; }
      res.writeHead(200).end(fs.readFileSync(file));
    });
    await new Promise((r) => server.listen(0, '127.0.0.1', r));
    try {
      const page = await context.newPage();
      const base = `http://127.0.0.1:${server.address().port}/`;
      const foreign = [];
      page.on('request', (r) => { if (!r.url().startsWith(base)) foreign.push(r.url()); });
      await page.goto(`${base}index.html#colour=target-residue`);
      await waitReady(page);
      assert.deepEqual(foreign, []);
      const frames = await page.evaluate(() => window.skinmeshViewer.frames());
      assert.equal(frames.length, frameTimes().length);
      assert.ok(covered(await pixels(page)) > 0.05 * WIDTH * HEIGHT);
      assert.equal(fs.readFileSync(path.join(root, 'index.html'), 'utf8').includes('data-file='), false, 'the page holds data');
    } finally {
      server.close();
    }
  },
};

if (!cases[testCase]) {
  console.error(`unknown case ${testCase}: one of ${Object.keys(cases).join(' ')}`);
  process.exit(2);
}
if (!fs.existsSync(path.join(fixtures, 'morph.html'))) {
  console.error(`${fixtures}: no fixtures (make_fixtures.sh makes them)`);
  process.exit(1);
}
const started = Date.now();
if (process.env.SKINMESH_TEST_TIMES) {
  const wrapped = cases[testCase];
  cases[testCase] = async (context) => { console.log(`browser up in ${Date.now() - started} ms`); return wrapped(context); };
}
await withBrowser(cases[testCase]);
console.log(`${testCase}: passed in ${((Date.now() - started) / 1000).toFixed(1)} s`);
