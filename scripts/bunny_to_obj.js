#!/usr/bin/env node
// Converts the npm package "bunny" ({positions, cells}, 0-based triangles) to a
// Wavefront OBJ with area-weighted vertex normals, so the bunny shades smoothly.
// Usage: node scripts/bunny_to_obj.js path/to/package/index.js out.obj
'use strict';
const fs = require('fs');
const path = require('path');

if (process.argv.length !== 4) {
  console.error('usage: bunny_to_obj.js <bunny index.js> <out.obj>');
  process.exit(2);
}
const bunny = require(path.resolve(process.argv[2]));
const positions = bunny.positions;
const cells = bunny.cells;
if (!Array.isArray(positions) || !Array.isArray(cells) || cells.length === 0) {
  console.error('bunny_to_obj: package does not export {positions, cells}');
  process.exit(1);
}

// The cross product of two edges is twice the area times the unit normal, so
// summing it weights each face by its area.
const normals = positions.map(() => [0, 0, 0]);
for (const [a, b, c] of cells) {
  const pa = positions[a], pb = positions[b], pc = positions[c];
  const e1 = [pb[0] - pa[0], pb[1] - pa[1], pb[2] - pa[2]];
  const e2 = [pc[0] - pa[0], pc[1] - pa[1], pc[2] - pa[2]];
  const n = [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]];
  for (const i of [a, b, c]) for (let k = 0; k < 3; ++k) normals[i][k] += n[k];
}

const lines = [
  '# Stanford bunny (Stanford 3D Scanning Repository) from the npm package "bunny",',
  '# converted by scripts/bunny_to_obj.js. Units as in the package (about 10 tall), y up.',
  `# ${positions.length} vertices, ${cells.length} triangles.`,
];
for (const p of positions) lines.push(`v ${p[0]} ${p[1]} ${p[2]}`);
for (const n of normals) {
  const len = Math.hypot(n[0], n[1], n[2]) || 1;
  lines.push(`vn ${(n[0] / len).toFixed(6)} ${(n[1] / len).toFixed(6)} ${(n[2] / len).toFixed(6)}`);
}
lines.push('o bunny');
for (const [a, b, c] of cells) lines.push(`f ${a + 1}//${a + 1} ${b + 1}//${b + 1} ${c + 1}//${c + 1}`);
fs.writeFileSync(process.argv[3], lines.join('\n') + '\n');
