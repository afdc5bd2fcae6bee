// The tests' own reader of skinmesh's binary little-endian PLY files (kept
// apart from the viewer's, so that the viewer is checked against another
// reading of the files): positions as doubles, every scalar vertex property.
import fs from 'node:fs';

const sizes = { char: 1, uchar: 1, short: 2, ushort: 2, int: 4, uint: 4, float: 4, double: 8 };
const getters = { char: 'getInt8', uchar: 'getUint8', short: 'getInt16', ushort: 'getUint16', int: 'getInt32',
                  uint: 'getUint32', float: 'getFloat32', double: 'getFloat64' };

export function readPly(file) {
  const bytes = fs.readFileSync(file);
  const end = bytes.indexOf('end_header\n');
  const head = bytes.subarray(0, end).toString('latin1').split('\n');
  if (!head.includes('format binary_little_endian 1.0')) throw new Error(`${file}: not binary little-endian`);
  const elements = [];
  for (const line of head) {
    const w = line.split(' ');
    if (w[0] === 'element') elements.push({ name: w[1], count: Number(w[2]), props: [] });
    if (w[0] === 'property') elements.at(-1).props.push(w[1] === 'list' ? { list: [w[2], w[3]], name: w[4] } : { type: w[1], name: w[2] });
  }
  const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  let at = end + 'end_header\n'.length;
  const read = (type) => { const v = view[getters[type]](at, true); at += sizes[type]; return v; };
  const out = { positions: [], properties: {}, triangles: [] };
  for (const e of elements) {
    for (const p of e.props) if (!p.list && e.name === 'vertex') out.properties[p.name] = [];
    for (let i = 0; i < e.count; ++i)
      for (const p of e.props) {
        if (p.list) {
          const n = read(p.list[0]);
          for (let c = 0; c < n; ++c) out.triangles.push(read(p.list[1]));
        } else if (e.name === 'vertex') out.properties[p.name].push(read(p.type));
        else read(p.type);
      }
  }
  const { x, y, z } = out.properties;
  for (let i = 0; i < x.length; ++i) out.positions.push(x[i], y[i], z[i]);
  return out;
}
