// three.js's own Ray.intersectTriangle (npm `three`), run by node on cases
// exported by rayaudit, for `rayaudit audit --grade`:
//
//   ci/fetch-corpus.sh        # npm pack three into ${RAYAUDIT_CACHE:-~/.cache/rayaudit}/corpus/npm/three
//   rayaudit audit --export-cases cases.csv --numbers decimal --families edge,vertex,closed-mesh
//   node examples/grade/three_intersect_triangle.mjs THREE_DIR cases.csv three.csv
//   rayaudit audit --grade three.csv --cases cases.csv --json graded.json
//
// JavaScript has no hex-float parser, so the cases are exported as decimals
// that read back exactly (--numbers decimal); Number() reads them exactly
// and String() writes t as the shortest decimal that reads back the same,
// so nothing is rounded on the way. The ray is two-sided (backfaceCulling
// false) with an unbounded far end, as the export's rays are. t is the one
// three.js computes: intersectTriangle returns the point ray.at(t), so the
// ray's `at` is wrapped to keep the t it is given.
import { readFileSync, writeFileSync } from "node:fs";
import { join } from "node:path";
import { pathToFileURL } from "node:url";

if (process.argv.length !== 5) {
  console.error("usage: node three_intersect_triangle.mjs THREE_DIR CASES.csv ANSWERS.csv");
  process.exit(2);
}
const [threeDir, casesPath, answersPath] = process.argv.slice(2);
const THREE = await import(pathToFileURL(join(threeDir, "build", "three.module.js")).href);

// The export's first line is its stamp (# rayaudit-cases version=... seed=...):
// comment lines are skipped, the first other line is the header.
const lines = readFileSync(casesPath, "utf8")
  .split(/\r?\n/)
  .filter((l) => !l.startsWith("#"));
const header = lines[0].split(",");
const col = Object.fromEntries(header.map((name, i) => [name, i]));
for (const name of ["id", "ox", "oy", "oz", "dx", "dy", "dz", "ax", "ay", "az", "bx", "by", "bz", "cx", "cy", "cz"]) {
  if (!(name in col)) {
    console.error(`${casesPath}:1: missing column '${name}'`);
    process.exit(2);
  }
}

const ray = new THREE.Ray();
let lastT = null;
const at = ray.at.bind(ray);
ray.at = (t, target) => ((lastT = t), at(t, target));
const a = new THREE.Vector3(), b = new THREE.Vector3(), c = new THREE.Vector3(), hit = new THREE.Vector3();
const out = ["id,hit,t"];
for (let i = 1; i < lines.length; ++i) {
  if (!lines[i].trim()) continue;
  const f = lines[i].split(",");
  const n = (name) => {
    const v = Number(f[col[name]]);
    if (!Number.isFinite(v)) {
      console.error(`${casesPath}:${i + 1}: column '${name}': '${f[col[name]]}' is not a number (export with --numbers decimal)`);
      process.exit(2);
    }
    return v;
  };
  ray.origin.set(n("ox"), n("oy"), n("oz"));
  ray.direction.set(n("dx"), n("dy"), n("dz"));
  a.set(n("ax"), n("ay"), n("az"));
  b.set(n("bx"), n("by"), n("bz"));
  c.set(n("cx"), n("cy"), n("cz"));
  lastT = null;
  const p = ray.intersectTriangle(a, b, c, false, hit);
  out.push(`${f[col.id]},${p ? "true" : "false"},${p ? String(lastT) : ""}`);
}
writeFileSync(answersPath, out.join("\n") + "\n");
console.log(`three.js r${THREE.REVISION}: ${out.length - 1} cases answered into ${answersPath}`);
