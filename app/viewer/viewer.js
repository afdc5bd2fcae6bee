// skinmesh viewer: a mesh or a morph of molecular skin surfaces in plain
// WebGL2, no library. The page's manifest names the files (PLY frames, atom
// tables); each is either embedded in the page (gzip, base64) or fetched by
// its relative address (no-embed pages, served from the morph's directory).
// The view's state lives in the address's fragment (#t=0.5&colour=residue&
// yaw=30&pitch=-20&zoom=1&speed=2&play=0) so that a view can be shared.
'use strict';

(() => {
  const manifest = JSON.parse(document.getElementById('skinmesh-manifest').textContent);
  const $ = (id) => document.getElementById(id);

  // ---------------------------------------------------------------- files

  function base64Bytes(text) {
    const raw = atob(text.replace(/\s+/g, ''));
    const bytes = new Uint8Array(raw.length);
    for (let i = 0; i < raw.length; ++i) bytes[i] = raw.charCodeAt(i);
    return bytes;
  }

  async function gunzip(bytes) {
    const stream = new Blob([bytes]).stream().pipeThrough(new DecompressionStream('gzip'));
    return new Uint8Array(await new Response(stream).arrayBuffer());
  }

  // The bytes of a file the manifest names: embedded, or beside the page.
  async function fileBytes(name) {
    for (const el of document.querySelectorAll('script[data-file]'))
      if (el.dataset.file === name) return gunzip(base64Bytes(el.textContent));
    let response;
    try {
      response = await fetch(name);
    } catch (e) {
      throw new Error(`${name}: cannot be fetched (${e.message}). A page written with --no-embed reads its files ` +
                      'by their addresses: serve its directory, e.g. python3 -m http.server, and open it from there');
    }
    if (!response.ok) throw new Error(`${name}: ${response.status} ${response.statusText}`);
    return new Uint8Array(await response.arrayBuffer());
  }

  // ---------------------------------------------------------------- PLY

  const plyTypes = {
    char: ['getInt8', 1], int8: ['getInt8', 1], uchar: ['getUint8', 1], uint8: ['getUint8', 1],
    short: ['getInt16', 2], int16: ['getInt16', 2], ushort: ['getUint16', 2], uint16: ['getUint16', 2],
    int: ['getInt32', 4], int32: ['getInt32', 4], uint: ['getUint32', 4], uint32: ['getUint32', 4],
    float: ['getFloat32', 4], float32: ['getFloat32', 4], double: ['getFloat64', 8], float64: ['getFloat64', 8],
  };

  function plyHeader(bytes, name) {
    const head = new TextDecoder('latin1').decode(bytes.subarray(0, Math.min(bytes.length, 65536)));
    const end = head.indexOf('end_header');
    if (!head.startsWith('ply') || end < 0) throw new Error(`${name}: not a PLY file`);
    const header = { format: '', elements: [], body: head.indexOf('\n', end) + 1 };
    for (const line of head.slice(0, end).split(/\r?\n/)) {
      const w = line.trim().split(/\s+/);
      if (w[0] === 'format') header.format = w[1];
      else if (w[0] === 'element') header.elements.push({ name: w[1], count: Number(w[2]), properties: [] });
      else if (w[0] === 'property') {
        const p = w[1] === 'list' ? { list: true, countType: w[2], type: w[3], name: w[4] } : { type: w[1], name: w[2] };
        if (!plyTypes[p.type] || (p.list && !plyTypes[p.countType])) throw new Error(`${name}: PLY type ${line}`);
        header.elements[header.elements.length - 1].properties.push(p);
      }
    }
    return header;
  }

  // A reader of the body's values one after another, binary or text.
  function plyValues(bytes, header) {
    if (header.format === 'ascii') {
      const words = new TextDecoder().decode(bytes.subarray(header.body)).trim().split(/\s+/);
      let at = 0;
      return () => Number(words[at++]);
    }
    const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
    const little = header.format === 'binary_little_endian';
    let at = header.body;
    return (type) => {
      const [get, size] = plyTypes[type];
      const v = view[get](at, little);
      at += size;
      return v;
    };
  }

  // Positions, triangles and every scalar vertex property by name.
  function parsePly(bytes, name) {
    const header = plyHeader(bytes, name);
    const next = plyValues(bytes, header);
    const mesh = { positions: null, triangles: [], properties: {} };
    for (const e of header.elements) {
      if (e.name === 'vertex') {
        mesh.positions = new Float32Array(3 * e.count);
        const columns = e.properties.map((p) => (p.list ? null : new Float64Array(e.count)));
        for (let i = 0; i < e.count; ++i)
          e.properties.forEach((p, k) => {
            if (p.list) { for (let c = next(p.countType); c > 0; --c) next(p.type); return; }
            columns[k][i] = next(p.type);
          });
        e.properties.forEach((p, k) => {
          const xyz = ['x', 'y', 'z'].indexOf(p.name);
          if (xyz >= 0) for (let i = 0; i < e.count; ++i) mesh.positions[3 * i + xyz] = columns[k][i];
          else if (columns[k]) mesh.properties[p.name] = columns[k];
        });
      } else {
        for (let i = 0; i < e.count; ++i)
          for (const p of e.properties) {
            if (!p.list) { next(p.type); continue; }
            const corners = [];
            for (let c = next(p.countType); c > 0; --c) corners.push(next(p.type));
            if (e.name === 'face' && (p.name === 'vertex_indices' || p.name === 'vertex_index'))
              for (let c = 2; c < corners.length; ++c) mesh.triangles.push(corners[0], corners[c - 1], corners[c]);
          }
      }
    }
    if (!mesh.positions) throw new Error(`${name}: no vertices`);
    mesh.triangles = Uint32Array.from(mesh.triangles);
    return mesh;
  }

  // ---------------------------------------------------------------- atom tables

  const atomColumns = ['index', 'chain', 'residue_number', 'insertion_code', 'residue_name', 'atom_name', 'element', 'radius'];

  function parseAtoms(text, name) {
    const lines = text.split(/\r?\n/).filter((l) => l.length);
    const head = lines[0].split('\t');
    const at = Object.fromEntries(atomColumns.map((c) => [c, head.indexOf(c)]));
    const lacking = atomColumns.filter((c) => at[c] < 0);
    if (lacking.length) throw new Error(`${name}: the header lacks ${lacking.join(', ')}`);
    const atoms = [];
    for (const line of lines.slice(1)) {
      const w = line.split('\t');
      const a = Object.fromEntries(atomColumns.map((c) => [c, w[at[c]] ?? '']));
      atoms[Number(a.index)] = a;
    }
    return atoms;
  }

  // ---------------------------------------------------------------- per-vertex atoms

  // A vertex's atom on one side, or -1: read by name. A frame marks a side
  // the vertex lacks by has_source_atom or has_target_atom = 0; frames
  // written before those flags, by -1.
  function sideAtoms(props, side, n) {
    const column = side === 'mesh' ? props.atom || props.atomid : props[`${side}_atom`];
    const present = props[`has_${side}_atom`];
    const out = new Int32Array(n).fill(-1);
    if (!column) return out;
    for (let i = 0; i < n; ++i) {
      const v = column[i];
      out[i] = v < 0 || v >= 4294967295 || (present && !present[i]) ? -1 : v;
    }
    return out;
  }

  // ---------------------------------------------------------------- colours

  const patchColours = [[0.45, 0.65, 0.90], [0.98, 0.80, 0.40], [0.95, 0.55, 0.35], [0.85, 0.35, 0.40]];
  const elementColours = { C: [0.72, 0.72, 0.72], N: [0.40, 0.52, 0.92], O: [0.92, 0.38, 0.35],
                           S: [0.95, 0.85, 0.35], P: [0.98, 0.60, 0.25], H: [0.95, 0.95, 0.95] };
  const noColour = [0.55, 0.55, 0.58];

  function hsl(h, s, l) {
    const f = (n) => {
      const k = (n + h * 12) % 12;
      return l - s * Math.min(l, 1 - l) * Math.max(-1, Math.min(k - 3, 9 - k, 1));
    };
    return [f(0), f(8), f(4)];
  }
  // The k-th of a sequence of hues that tells neighbours apart (golden ratio steps).
  const distinct = (k) => hsl((k * 0.6180339887) % 1, 0.55, 0.6);

  function ramp(x) {  // 0 -> red, 0.5 -> yellow, 1 -> blue-green
    const stops = [[0.80, 0.15, 0.15], [0.97, 0.85, 0.30], [0.25, 0.62, 0.75]];
    const u = Math.max(0, Math.min(1, x)) * 2, k = Math.min(1, Math.floor(u)), f = u - k;
    return stops[k].map((c, i) => c + f * (stops[k + 1][i] - c));
  }

  // Ordinals of chains and residues in an atom table, for their hues.
  function keyOrdinals(atoms, key) {
    const seen = new Map();
    return atoms.map((a) => {
      const k = key(a);
      if (!seen.has(k)) seen.set(k, seen.size);
      return seen.get(k);
    });
  }

  // ---------------------------------------------------------------- the scene

  const scene = { kind: manifest.kind, frames: [], tables: {}, notes: [] };

  async function loadScene() {
    for (const [side, file] of Object.entries(manifest.atoms || {})) {
      if (!file) continue;
      try {
        const atoms = parseAtoms(new TextDecoder().decode(await fileBytes(file)), file);
        scene.tables[side] = {
          atoms,
          chain: keyOrdinals(atoms, (a) => a.chain),
          residue: keyOrdinals(atoms, (a) => `${a.chain}:${a.residue_number}:${a.insertion_code}`),
        };
      } catch (e) {
        scene.notes.push(`${file}: ${e.message}`);
      }
    }
    for (const f of manifest.frames) {
      const mesh = parsePly(await fileBytes(f.file), f.file);
      const n = mesh.positions.length / 3, p = mesh.properties;
      const frame = { t: f.t, file: f.file, ...mesh, n };
      frame.patch = p.patch;
      frame.atoms = scene.kind === 'mesh' ? { mesh: sideAtoms(p, 'mesh', n) }
        : { source: sideAtoms(p, 'source', n), target: sideAtoms(p, 'target', n) };
      frame.ids = p.id || null;
      frame.minAngle = smallestAngles(mesh.positions, mesh.triangles);
      scene.frames.push(frame);
    }
    linkFrames();
    scene.bounds = bounds();
  }

  // Per frame: where each vertex's id is in the next frame, and its age
  // (how many frames its id has lived, this one included).
  function linkFrames() {
    scene.frames.forEach((f, k) => {
      f.age = new Int32Array(f.n).fill(1);
      if (!f.ids) return;
      f.index = new Map();
      for (let i = 0; i < f.n; ++i) f.index.set(f.ids[i], i);
      const before = scene.frames[k - 1];
      if (before && before.index)
        for (let i = 0; i < f.n; ++i) {
          const j = before.index.get(f.ids[i]);
          if (j !== undefined) f.age[i] = before.age[j] + 1;
        }
    });
  }

  function bounds() {
    const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
    for (const f of scene.frames)
      for (let i = 0; i < f.positions.length; ++i) {
        lo[i % 3] = Math.min(lo[i % 3], f.positions[i]);
        hi[i % 3] = Math.max(hi[i % 3], f.positions[i]);
      }
    const centre = lo.map((v, i) => (v + hi[i]) / 2);
    let radius = 0;
    for (const f of scene.frames)
      for (let i = 0; i < f.positions.length; i += 3)
        radius = Math.max(radius, Math.hypot(f.positions[i] - centre[0], f.positions[i + 1] - centre[1],
                                             f.positions[i + 2] - centre[2]));
    return { centre, radius: Math.max(radius, 1e-6) };
  }

  function smallestAngles(pos, tri) {
    const out = new Float32Array(tri.length / 3);
    const side = (a, b) => Math.hypot(pos[3 * a] - pos[3 * b], pos[3 * a + 1] - pos[3 * b + 1], pos[3 * a + 2] - pos[3 * b + 2]);
    for (let k = 0; k < out.length; ++k) {
      const [a, b, c] = [tri[3 * k], tri[3 * k + 1], tri[3 * k + 2]];
      const l = [side(b, c), side(c, a), side(a, b)].sort((x, y) => x - y);
      // The smallest angle faces the shortest side (law of cosines).
      const cos = (l[1] * l[1] + l[2] * l[2] - l[0] * l[0]) / (2 * l[1] * l[2]);
      out[k] = Math.acos(Math.max(-1, Math.min(1, cos))) * 180 / Math.PI;
    }
    return out;
  }

  // The two frames around t and the share s of the way between them.
  function bracket(t) {
    const fr = scene.frames;
    if (fr.length === 1 || t <= fr[0].t) return { a: 0, b: 0, s: 0 };
    for (let k = 0; k + 1 < fr.length; ++k)
      if (t <= fr[k + 1].t) return { a: k, b: k + 1, s: (t - fr[k].t) / Math.max(1e-12, fr[k + 1].t - fr[k].t) };
    return { a: fr.length - 1, b: fr.length - 1, s: 0 };
  }

  // Frame `from`'s vertices at share s of the way to frame `to`: a vertex
  // whose id `to` also has moves on the straight line between its two
  // places; the rest stay where `from` has them (and fade with the frame).
  function movedPositions(from, to, s) {
    const out = Float32Array.from(from.positions);
    if (from === to || !from.ids || !to.index) return out;
    const f = from.positions, g = to.positions;
    for (let i = 0; i < from.n; ++i) {
      const j = to.index.get(from.ids[i]);
      if (j === undefined) continue;
      for (let c = 0; c < 3; ++c) out[3 * i + c] = f[3 * i + c] + s * (g[3 * j + c] - f[3 * i + c]);
    }
    return out;
  }

  // The read-only hook the tests use: the vertices of the frames around t at t.
  function positionsAt(t) {
    const { a, b, s } = bracket(t);
    const fa = scene.frames[a], fb = scene.frames[b];
    const pack = (f, p) => ({ file: f.file, ids: f.ids ? Array.from(f.ids) : null, positions: Array.from(p) });
    return { s, from: pack(fa, movedPositions(fa, fb, s)), to: pack(fb, movedPositions(fb, fa, 1 - s)) };
  }

  // ---------------------------------------------------------------- colour modes

  const modes = {
    chain: { label: 'chain', table: true, vertex: (f, i, side) => tableColour(f, i, side, (T, k) => distinct(T.chain[k])) },
    residue: { label: 'residue', table: true, mesh: true, vertex: (f, i, side) => tableColour(f, i, side, (T, k) => distinct(T.residue[k])) },
    'source-residue': { label: 'source residue', table: 'source', morph: true,
                        vertex: (f, i) => tableColour(f, i, 'source', (T, k) => distinct(T.residue[k])) },
    'target-residue': { label: 'target residue', table: 'target', morph: true,
                        vertex: (f, i) => tableColour(f, i, 'target', (T, k) => distinct(T.residue[k])) },
    element: { label: 'element', table: true,
               vertex: (f, i, side) => tableColour(f, i, side, (T, k) => elementColours[T.atoms[k].element] || [0.85, 0.55, 0.85]) },
    atom: { label: 'atom index', vertex: (f, i, side) => { const k = vertexAtom(f, i, side).index; return k < 0 ? noColour : distinct(k); } },
    patch: { label: 'patch type', vertex: (f, i) => (f.patch ? patchColours[f.patch[i]] || noColour : noColour) },
    age: { label: 'vertex age', morph: true, vertex: (f, i) => ramp((f.age[i] - 1) / Math.max(1, scene.frames.length - 1)) },
    quality: { label: 'triangle quality (smallest angle)', triangle: (f, k) => ramp(f.minAngle[k] / 60) },
  };

  // The atom of vertex i: in a mesh its own; in a morph the side asked for,
  // else the source side, else the target side.
  function vertexAtom(f, i, side) {
    if (scene.kind === 'mesh') return { side: 'mesh', index: f.atoms.mesh[i] };
    for (const s of side ? [side] : ['source', 'target']) if (f.atoms[s][i] >= 0) return { side: s, index: f.atoms[s][i] };
    return { side: side || 'source', index: -1 };
  }

  function tableColour(f, i, side, pick) {
    const { side: s, index } = vertexAtom(f, i, side);
    const T = scene.tables[s];
    return T && index >= 0 && T.atoms[index] ? pick(T, index) : noColour;
  }

  function modeAvailable(name) {
    const m = modes[name];
    if (m.morph && scene.kind !== 'morph') return false;
    if (m.mesh && scene.kind !== 'mesh') return false;
    if (name === 'age' && !scene.frames[0].ids) return false;
    if (m.table === true) return Object.keys(scene.tables).length > 0;
    if (m.table) return !!scene.tables[m.table];
    return true;
  }

  function colours(f, mode) {
    const c = new Float32Array(9 * f.triangles.length / 3);
    const m = modes[mode];
    const perVertex = m.vertex ? Array.from({ length: f.n }, (_, i) => m.vertex(f, i)) : null;
    for (let k = 0; k < f.triangles.length / 3; ++k)
      for (let v = 0; v < 3; ++v) c.set(perVertex ? perVertex[f.triangles[3 * k + v]] : m.triangle(f, k), 9 * k + 3 * v);
    return c;
  }

  // ---------------------------------------------------------------- WebGL

  const canvas = $('view');
  const gl = canvas.getContext('webgl2', { antialias: true, preserveDrawingBuffer: true });

  const vertexShader = `#version 300 es
    in vec3 a_position; in vec3 a_normal; in vec3 a_colour;
    uniform mat4 u_viewProjection; uniform mat4 u_view;
    out vec3 v_normal; out vec3 v_colour;
    void main() {
      v_normal = mat3(u_view) * a_normal;
      v_colour = a_colour;
      gl_Position = u_viewProjection * vec4(a_position, 1.0);
    }`;
  // Lambert with an ambient term and a little specular light from the
  // viewer's upper left, as skinmesh render shades. Two frames are shown at
  // once by dissolving (screen-door transparency: each pixel keeps one of
  // them by a fixed noise), which needs no sorting and keeps depth right.
  const fragmentShader = `#version 300 es
    precision highp float;
    in vec3 v_normal; in vec3 v_colour;
    uniform float u_share; uniform int u_second;
    out vec4 colour;
    void main() {
      float noise = fract(52.9829189 * fract(dot(gl_FragCoord.xy, vec2(0.06711056, 0.00583715))));
      if ((u_second == 0) == (noise < u_share)) discard;
      vec3 n = normalize(gl_FrontFacing ? v_normal : -v_normal);
      vec3 light = normalize(vec3(-0.4, 0.5, 0.77));
      vec3 halfway = normalize(light + vec3(0.0, 0.0, 1.0));
      float shade = 0.28 + 0.72 * max(0.0, dot(n, light)) + 0.18 * pow(max(0.0, dot(n, halfway)), 40.0);
      colour = vec4(min(vec3(1.0), v_colour * shade), 1.0);
    }`;

  function compile(type, source) {
    const s = gl.createShader(type);
    gl.shaderSource(s, source);
    gl.compileShader(s);
    if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(s));
    return s;
  }

  function makeProgram() {
    const p = gl.createProgram();
    gl.attachShader(p, compile(gl.VERTEX_SHADER, vertexShader));
    gl.attachShader(p, compile(gl.FRAGMENT_SHADER, fragmentShader));
    gl.linkProgram(p);
    if (!gl.getProgramParameter(p, gl.LINK_STATUS)) throw new Error(gl.getProgramInfoLog(p));
    return p;
  }

  // One drawable mesh: de-indexed triangles (a colour per corner, so that a
  // triangle's own value, its quality, colours it whole).
  function makeDrawable(program) {
    const vao = gl.createVertexArray();
    gl.bindVertexArray(vao);
    const buffers = {};
    for (const name of ['a_position', 'a_normal', 'a_colour']) {
      buffers[name] = gl.createBuffer();
      gl.bindBuffer(gl.ARRAY_BUFFER, buffers[name]);
      const at = gl.getAttribLocation(program, name);
      gl.enableVertexAttribArray(at);
      gl.vertexAttribPointer(at, 3, gl.FLOAT, false, 0, 0);
    }
    return { vao, buffers, count: 0, key: { geometry: null, colour: null } };
  }

  function vertexNormals(pos, tri) {
    const n = new Float32Array(pos.length);
    for (let k = 0; k < tri.length; k += 3) {
      const [a, b, c] = [tri[k], tri[k + 1], tri[k + 2]];
      const u = [0, 1, 2].map((i) => pos[3 * b + i] - pos[3 * a + i]);
      const v = [0, 1, 2].map((i) => pos[3 * c + i] - pos[3 * a + i]);
      const f = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]];
      for (const p of [a, b, c]) for (let i = 0; i < 3; ++i) n[3 * p + i] += f[i];
    }
    return n;
  }

  function upload(d, name, data) {
    gl.bindBuffer(gl.ARRAY_BUFFER, d.buffers[name]);
    gl.bufferData(gl.ARRAY_BUFFER, data, gl.DYNAMIC_DRAW);
  }

  function setGeometry(d, f, pos) {
    const nrm = vertexNormals(pos, f.triangles), tri = f.triangles;
    const p = new Float32Array(3 * tri.length), n = new Float32Array(3 * tri.length);
    for (let k = 0; k < tri.length; ++k)
      for (let i = 0; i < 3; ++i) {
        p[3 * k + i] = pos[3 * tri[k] + i];
        n[3 * k + i] = nrm[3 * tri[k] + i];
      }
    upload(d, 'a_position', p);
    upload(d, 'a_normal', n);
    d.count = tri.length;
    d.positions = pos;
    d.frame = f;
  }

  // ---------------------------------------------------------------- matrices (column-major)

  function multiply(a, b) {
    const o = new Float32Array(16);
    for (let c = 0; c < 4; ++c)
      for (let r = 0; r < 4; ++r) {
        let s = 0;
        for (let k = 0; k < 4; ++k) s += a[4 * k + r] * b[4 * c + k];
        o[4 * c + r] = s;
      }
    return o;
  }
  const translation = (x, y, z) => Float32Array.of(1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, x, y, z, 1);
  const rotationX = (a) => Float32Array.of(1, 0, 0, 0, 0, Math.cos(a), Math.sin(a), 0, 0, -Math.sin(a), Math.cos(a), 0, 0, 0, 0, 1);
  const rotationY = (a) => Float32Array.of(Math.cos(a), 0, -Math.sin(a), 0, 0, 1, 0, 0, Math.sin(a), 0, Math.cos(a), 0, 0, 0, 0, 1);
  function perspective(fovy, aspect, near, far) {
    const f = 1 / Math.tan(fovy / 2);
    return Float32Array.of(f / aspect, 0, 0, 0, 0, f, 0, 0, 0, 0, (far + near) / (near - far), -1,
                           0, 0, 2 * far * near / (near - far), 0);
  }

  // The camera: turned by yaw about the vertical axis, then by pitch about
  // the horizontal one (as skinmesh render), at the distance that frames the
  // molecule at zoom 1 (fitDistance).
  const fov = 30 * Math.PI / 180;
  function camera(state, width, height) {
    // On a wide canvas the molecule is framed in the part the panel leaves.
    const ratio = width / canvas.clientWidth;
    const panel = canvas.clientWidth > 640 ? ($('panel').offsetWidth + 24) * ratio : 0;
    const aspect = width / height, free = (width - panel) / height;
    const turn = multiply(rotationX(state.pitch * Math.PI / 180), rotationY(state.yaw * Math.PI / 180));
    if (!scene.fit) scene.fit = fitDistance(multiply(rotationX(defaults.pitch * Math.PI / 180), rotationY(defaults.yaw * Math.PI / 180)), free);
    const { centre, radius } = scene.bounds;
    const distance = scene.fit / state.zoom;
    const view = multiply(translation(0, 0, -distance), multiply(turn, translation(-centre[0], -centre[1], -centre[2])));
    const shift = translation(panel / width, 0, 0);  // in clip space: half the panel's width to the right
    const projection = multiply(shift, perspective(fov, aspect, Math.max(distance - 2 * radius, distance / 100), distance + 2 * radius));
    return { view, projection, viewProjection: multiply(projection, view) };
  }

  // The centre and the distance at zoom 1: every frame's vertices, seen
  // from the default view, inside the free part of the picture with 5% to
  // spare. The same for every view, so that turning does not zoom and a
  // shared fragment shows the same picture.
  function fitDistance(turn, aspect) {
    const seen = (centre, body) => {
      for (const f of scene.frames)
        for (let i = 0; i < f.positions.length; i += 3) {
          const p = [0, 1, 2].map((c) => f.positions[i + c] - centre[c]);
          body([0, 1, 2].map((r) => turn[r] * p[0] + turn[4 + r] * p[1] + turn[8 + r] * p[2]));
        }
    };
    // First the centre: the middle of the outline in this view.
    const lo = [Infinity, Infinity], hi = [-Infinity, -Infinity];
    seen(scene.bounds.centre, (q) => { for (const c of [0, 1]) { lo[c] = Math.min(lo[c], q[c]); hi[c] = Math.max(hi[c], q[c]); } });
    const mid = [(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2];
    scene.bounds.centre = scene.bounds.centre.map((v, c) => v + turn[4 * c] * mid[0] + turn[4 * c + 1] * mid[1]);
    const tanY = Math.tan(fov / 2), tanX = tanY * aspect;
    let distance = 0;
    scene.bounds.radius = 1e-6;  // about the new centre
    seen(scene.bounds.centre, (q) => {
      scene.bounds.radius = Math.max(scene.bounds.radius, Math.hypot(q[0], q[1], q[2]));
      distance = Math.max(distance, q[2] + 1.05 * Math.abs(q[0]) / tanX, q[2] + 1.05 * Math.abs(q[1]) / tanY);
    });
    return Math.max(distance, 2 * scene.bounds.radius / 10);
  }

  // ---------------------------------------------------------------- state and drawing

  const defaults = { t: 0, colour: '', yaw: 30, pitch: -20, zoom: 1, speed: 2, play: 0 };
  const state = { ...defaults };
  let program, drawables, dirty = true, playing = false, lastTick = 0;

  function readFragment() {
    const params = new URLSearchParams(location.hash.slice(1));
    for (const key of Object.keys(defaults)) {
      if (!params.has(key)) continue;
      const v = params.get(key);
      if (key === 'colour') state.colour = v;
      else if (Number.isFinite(Number(v))) state[key] = Number(v);
    }
    state.t = Math.max(tRange()[0], Math.min(tRange()[1], state.t));
    state.zoom = Math.max(0.05, Math.min(50, state.zoom));
    state.pitch = Math.max(-90, Math.min(90, state.pitch));
    if (!modes[state.colour] || !modeAvailable(state.colour)) {
      if (state.colour) scene.colourNote = `colour=${state.colour} is not available here: shown by ${firstMode()}`;
      state.colour = firstMode();
    }
    playing = state.play === 1 && scene.kind === 'morph';
  }

  // The frames' t: 0 to 1 for a morph, 0 to the last model's index for a trajectory.
  const tRange = () => [scene.frames[0].t, scene.frames[scene.frames.length - 1].t];

  function firstMode() {
    const preferred = scene.kind === 'morph' ? ['source-residue', 'patch'] : ['residue', 'patch'];
    return preferred.find((m) => modeAvailable(m)) || 'quality';
  }

  let fragmentTimer = 0;
  function writeFragment() {
    clearTimeout(fragmentTimer);
    fragmentTimer = setTimeout(() => {
      const round = (v) => String(Math.round(v * 1000) / 1000);
      const parts = [`colour=${state.colour}`, `yaw=${round(state.yaw)}`, `pitch=${round(state.pitch)}`, `zoom=${round(state.zoom)}`];
      if (scene.kind === 'morph') parts.unshift(`t=${round(state.t)}`), parts.push(`speed=${round(state.speed)}`, `play=${playing ? 1 : 0}`);
      history.replaceState(null, '', `#${parts.join('&')}`);
    }, 150);
  }

  function resize() {
    const ratio = window.devicePixelRatio || 1;
    const w = Math.round(canvas.clientWidth * ratio), h = Math.round(canvas.clientHeight * ratio);
    if (canvas.width !== w || canvas.height !== h) { canvas.width = w; canvas.height = h; }
  }

  // The two frames around state.t in the two drawables, each at the
  // interpolated positions, re-uploaded only when what they show changed.
  function prepare() {
    const { a, b, s } = bracket(state.t);
    const pairs = [[a, b, s], [b, a, 1 - s]];
    drawables.forEach((d, k) => {
      const [from, to, share] = pairs[k];
      const key = `${from}:${to}:${share}`;
      if (d.key.geometry !== key) {
        setGeometry(d, scene.frames[from], movedPositions(scene.frames[from], scene.frames[to], share));
        d.key.geometry = key;
      }
      if (d.key.colour !== `${from}:${state.colour}`) {
        upload(d, 'a_colour', colours(scene.frames[from], state.colour));
        d.key.colour = `${from}:${state.colour}`;
      }
    });
    return s;
  }

  function draw() {
    resize();
    const s = prepare();
    gl.viewport(0, 0, canvas.width, canvas.height);
    gl.clearColor(0.957, 0.961, 0.969, 1);
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
    gl.enable(gl.DEPTH_TEST);
    gl.useProgram(program);
    const cam = camera(state, canvas.width, canvas.height);
    gl.uniformMatrix4fv(gl.getUniformLocation(program, 'u_viewProjection'), false, cam.viewProjection);
    gl.uniformMatrix4fv(gl.getUniformLocation(program, 'u_view'), false, cam.view);
    gl.uniform1f(gl.getUniformLocation(program, 'u_share'), s);
    drawables.forEach((d, k) => {
      if ((k === 0 && s >= 1) || (k === 1 && s <= 0)) return;
      gl.uniform1i(gl.getUniformLocation(program, 'u_second'), k);
      gl.bindVertexArray(d.vao);
      gl.drawArrays(gl.TRIANGLES, 0, d.count);
    });
    placeMarker(cam.viewProjection);
    showState();
  }

  function frameLoop(now) {
    if (playing) {
      const [t0, t1] = tRange(), dt = lastTick ? (now - lastTick) / 1000 : 0;
      state.t += dt * state.speed * (t1 - t0 || 1) / Math.max(1, scene.frames.length - 1);
      if (state.t > t1) state.t = t0;
      dirty = true;
      writeFragment();
    }
    lastTick = now;
    if (dirty) { draw(); dirty = false; }
    requestAnimationFrame(frameLoop);
  }

  // ---------------------------------------------------------------- picking

  // The vertex under canvas point (x, y) in CSS pixels: the nearest
  // triangle the eye's ray meets (Moller-Trumbore), then its nearest corner.
  function pick(x, y) {
    const ratio = canvas.width / canvas.clientWidth;
    const cam = camera(state, canvas.width, canvas.height);
    const inv = invert(cam.viewProjection);
    const ndc = [2 * x * ratio / canvas.width - 1, 1 - 2 * y * ratio / canvas.height];
    const unproject = (z) => {
      const v = [0, 1, 2, 3].map((r) => inv[r] * ndc[0] + inv[4 + r] * ndc[1] + inv[8 + r] * z + inv[12 + r]);
      return [v[0] / v[3], v[1] / v[3], v[2] / v[3]];
    };
    const o = unproject(-1), e = unproject(1), dir = [e[0] - o[0], e[1] - o[1], e[2] - o[2]];
    const s = bracket(state.t).s;
    const d = drawables[s < 0.5 ? 0 : 1], f = d.frame, p = d.positions, tri = f.triangles;
    let best = null;
    for (let k = 0; k < tri.length; k += 3) {
      const hit = rayTriangle(o, dir, p, tri[k], tri[k + 1], tri[k + 2]);
      if (hit && (!best || hit.t < best.t)) best = { ...hit, k };
    }
    if (!best) return null;
    const w = [1 - best.u - best.v, best.u, best.v];
    const corner = w.indexOf(Math.max(...w));
    const vertex = tri[best.k + corner];
    return describe(f, vertex, [0, 1, 2].map((i) => p[3 * vertex + i]));
  }

  function rayTriangle(o, d, p, a, b, c) {
    const e1 = [0, 1, 2].map((i) => p[3 * b + i] - p[3 * a + i]), e2 = [0, 1, 2].map((i) => p[3 * c + i] - p[3 * a + i]);
    const h = [d[1] * e2[2] - d[2] * e2[1], d[2] * e2[0] - d[0] * e2[2], d[0] * e2[1] - d[1] * e2[0]];
    const det = e1[0] * h[0] + e1[1] * h[1] + e1[2] * h[2];
    if (Math.abs(det) < 1e-12) return null;
    const s = [0, 1, 2].map((i) => o[i] - p[3 * a + i]);
    const u = (s[0] * h[0] + s[1] * h[1] + s[2] * h[2]) / det;
    if (u < 0 || u > 1) return null;
    const q = [s[1] * e1[2] - s[2] * e1[1], s[2] * e1[0] - s[0] * e1[2], s[0] * e1[1] - s[1] * e1[0]];
    const v = (d[0] * q[0] + d[1] * q[1] + d[2] * q[2]) / det;
    if (v < 0 || u + v > 1) return null;
    const t = (e2[0] * q[0] + e2[1] * q[1] + e2[2] * q[2]) / det;
    return t > 0 ? { t, u, v } : null;
  }

  function invert(m) {  // a 4x4 inverse by cofactors
    const a = Array.from(m), inv = new Array(16);
    const idx = (r, c) => 4 * c + r;
    for (let r = 0; r < 4; ++r)
      for (let c = 0; c < 4; ++c) {
        const rows = [0, 1, 2, 3].filter((i) => i !== c), cols = [0, 1, 2, 3].filter((i) => i !== r);
        const m3 = (i, j) => a[idx(rows[i], cols[j])];
        const det3 = m3(0, 0) * (m3(1, 1) * m3(2, 2) - m3(1, 2) * m3(2, 1)) - m3(0, 1) * (m3(1, 0) * m3(2, 2) - m3(1, 2) * m3(2, 0)) +
                     m3(0, 2) * (m3(1, 0) * m3(2, 1) - m3(1, 1) * m3(2, 0));
        inv[idx(r, c)] = ((r + c) % 2 ? -1 : 1) * det3;
      }
    let det = 0;
    for (let c = 0; c < 4; ++c) det += a[idx(0, c)] * inv[idx(c, 0)];
    return inv.map((v) => v / det);
  }

  function describe(f, vertex, position) {
    const out = { file: f.file, vertex, position, atoms: {} };
    for (const side of Object.keys(f.atoms)) {
      const index = f.atoms[side][vertex];
      const a = scene.tables[side] && index >= 0 ? scene.tables[side].atoms[index] : null;
      out.atoms[side] = { index, table: !!scene.tables[side], ...(a ? { chain: a.chain, residue_number: a.residue_number, insertion_code: a.insertion_code,
                                           residue_name: a.residue_name, atom_name: a.atom_name, element: a.element } : {}) };
    }
    return out;
  }

  // The picked point's dot, where the point is in this view (kept while the view turns).
  function placeMarker(viewProjection) {
    const p = window.skinmeshViewer && window.skinmeshViewer.lastPick, el = $('marker');
    if (!p) { el.style.display = 'none'; return; }
    const v = [0, 1, 2, 3].map((r) => viewProjection[r] * p.position[0] + viewProjection[4 + r] * p.position[1] +
                                       viewProjection[8 + r] * p.position[2] + viewProjection[12 + r]);
    el.style.left = `${(v[0] / v[3] + 1) / 2 * canvas.clientWidth}px`;
    el.style.top = `${(1 - v[1] / v[3]) / 2 * canvas.clientHeight}px`;
    el.style.display = 'block';
  }

  function pickText(p) {
    if (!p) return 'nothing under the pointer';
    const line = (side, a) => {
      const name = side === 'mesh' ? 'atom' : `${side} atom`;
      if (a.index < 0) return `${name}: none`;
      if (!a.atom_name) return `${name} ${a.index} (${a.table ? 'not in the atom table' : 'no atom table'})`;
      return `${name} ${a.index}: ${a.atom_name} of ${a.residue_name} ${a.residue_number}${a.insertion_code}, chain ${a.chain || '-'}`;
    };
    return [`vertex ${p.vertex} of ${p.file}`, ...Object.entries(p.atoms).map(([s, a]) => line(s, a))].join('\n');
  }

  // ---------------------------------------------------------------- controls

  function showState() {
    $('t').value = state.t;
    $('t-value').textContent = `t = ${state.t.toFixed(3)}`;
    $('play').textContent = playing ? 'Pause' : 'Play';
    $('colour').value = state.colour;
    const speed = $('speed');
    if (![...speed.options].some((o) => Number(o.value) === state.speed)) speed.add(new Option(`${state.speed} frames/s`, state.speed));
    speed.value = String(state.speed);
  }

  function legend() {
    const m = state.colour, el = $('legend');
    const rampCss = `linear-gradient(to right, ${[0, 0.25, 0.5, 0.75, 1].map((x) => `rgb(${ramp(x).map((c) => Math.round(255 * c))})`).join(',')})`;
    if (m === 'quality') el.innerHTML = `<div class="ramp" style="background:${rampCss}"></div><div class="ends"><span>0&deg;</span><span>30&deg;</span><span>60&deg;</span></div>`;
    else if (m === 'age') el.innerHTML = `<div class="ramp" style="background:${rampCss}"></div><div class="ends"><span>new</span><span>${scene.frames.length} frames old</span></div>`;
    else if (m === 'patch') {
      const names = ['sphere (1 atom)', 'hyperboloid (2)', 'hyperboloid (3)', 'concave sphere (4)'];
      el.innerHTML = names.map((n, k) => `<span class="swatch" style="background:rgb(${patchColours[k].map((c) => Math.round(255 * c))})"></span>${n}`).join('<br>');
    } else el.textContent = { chain: 'a hue per chain', residue: 'a hue per residue', 'source-residue': 'a hue per source residue',
                              'target-residue': 'a hue per target residue', element: 'C grey, N blue, O red, S yellow, P orange',
                              atom: 'a hue per atom index' }[m] || '';
  }

  function setupControls() {
    $('title').textContent = manifest.title;
    const f0 = scene.frames[0];
    $('summary').textContent = scene.kind === 'morph'
      ? `${scene.frames.length} frames, ${f0.n} vertices at t = ${f0.t}`
      : `${f0.n} vertices, ${f0.triangles.length / 3} triangles`;
    const select = $('colour');
    for (const [name, m] of Object.entries(modes)) {
      if ((m.morph && scene.kind !== 'morph') || (m.mesh && scene.kind !== 'mesh')) continue;
      if (name === 'age' && !f0.ids) continue;
      const o = new Option(m.label + (modeAvailable(name) ? '' : ' (needs the atom table)'), name);
      o.disabled = !modeAvailable(name);
      select.add(o);
    }
    const notes = [...scene.notes];
    const missing = Object.entries(manifest.atoms || {}).filter(([s]) => !scene.tables[s]).map(([s, file]) => file || `${s} atoms`);
    if (missing.length) notes.push(`No atom table (${missing.join(', ')}): chain, residue and element colours are off; patch, quality, atom index${scene.kind === 'morph' ? ' and age' : ''} work.`);
    if (scene.colourNote) notes.push(scene.colourNote);
    $('note').textContent = notes.join(' ');
    if (scene.kind === 'morph') $('morph-controls').classList.remove('hidden');
    const [t0, t1] = tRange();
    Object.assign($('t'), { min: t0, max: t1, step: (t1 - t0) / 1000 || 0.001 });
    select.addEventListener('change', () => { state.colour = select.value; legend(); dirty = true; writeFragment(); });
    $('t').addEventListener('input', (e) => { state.t = Number(e.target.value); playing = false; dirty = true; writeFragment(); });
    $('play').addEventListener('click', () => { playing = !playing; lastTick = 0; dirty = true; writeFragment(); });
    $('speed').addEventListener('change', (e) => { state.speed = Number(e.target.value); writeFragment(); });
    setupPointer();
    window.addEventListener('resize', () => { dirty = true; });
    window.addEventListener('hashchange', () => { readFragment(); legend(); dirty = true; });
  }

  function setupPointer() {
    let drag = null;
    canvas.addEventListener('pointerdown', (e) => { drag = { x: e.clientX, y: e.clientY, moved: 0 }; canvas.setPointerCapture(e.pointerId); });
    canvas.addEventListener('pointermove', (e) => {
      if (!drag) return;
      const dx = e.clientX - drag.x, dy = e.clientY - drag.y;
      drag.moved += Math.abs(dx) + Math.abs(dy);
      drag.x = e.clientX; drag.y = e.clientY;
      state.yaw = (state.yaw + dx * 0.4) % 360;
      state.pitch = Math.max(-90, Math.min(90, state.pitch + dy * 0.4));
      dirty = true;
      writeFragment();
    });
    canvas.addEventListener('pointerup', (e) => {
      if (drag && drag.moved < 4) {
        const r = canvas.getBoundingClientRect();
        const p = pick(e.clientX - r.left, e.clientY - r.top);
        window.skinmeshViewer.lastPick = p;
        $('pick').textContent = pickText(p);
        dirty = true;
      }
      drag = null;
    });
    canvas.addEventListener('wheel', (e) => {
      e.preventDefault();
      state.zoom = Math.max(0.05, Math.min(50, state.zoom * Math.exp(-e.deltaY * 0.001)));
      dirty = true;
      writeFragment();
    }, { passive: false });
  }

  // ---------------------------------------------------------------- start

  async function start() {
    if (!gl) throw new Error('this browser gives no WebGL2 context');
    await loadScene();
    program = makeProgram();
    drawables = [makeDrawable(program), makeDrawable(program)];
    readFragment();
    setupControls();
    legend();
    draw();
    dirty = false;
    requestAnimationFrame(frameLoop);
    document.body.dataset.ready = '1';
  }

  window.skinmeshViewer = {
    positionsAt,
    pick: (x, y) => pick(x, y),
    state: () => ({ ...state, play: playing ? 1 : 0 }),
    frames: () => scene.frames.map((f) => ({ t: f.t, file: f.file, vertices: f.n, triangles: f.triangles.length / 3 })),
    colourModes: () => Object.keys(modes).filter((m) => modeAvailable(m)),
    drawNow: () => { draw(); return true; },
    lastPick: null,
  };
  window.skinmeshViewer.ready = start().catch((e) => {
    $('error').style.display = 'block';
    $('error').textContent = `The viewer could not start: ${e.message}`;
    document.body.dataset.error = e.message;
  });
})();
