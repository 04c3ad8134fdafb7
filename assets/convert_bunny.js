// Converts the npm package `bunny` (Stanford bunny as JSON positions and cells) to OBJ.
//   cd target/node && npm install bunny@1.0.1 && node ../../assets/convert_bunny.js > ../../assets/bunny.obj
// (tests/run.sh installs the package under target/node.)
const bunny = require(require.resolve('bunny', { paths: [process.cwd()] }));
const lines = ['# Stanford bunny from npm bunny@1.0.1 (public domain), converted by assets/convert_bunny.js'];
for (const p of bunny.positions) lines.push(`v ${p[0]} ${p[1]} ${p[2]}`);
for (const c of bunny.cells) lines.push(`f ${c[0] + 1} ${c[1] + 1} ${c[2] + 1}`);
process.stdout.write(lines.join('\n') + '\n');
