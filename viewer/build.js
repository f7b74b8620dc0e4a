#!/usr/bin/env node
// Builds the page template of `nhdyn view`:
//   dist/viewer.bundle.js  src/viewer.js with three.js and urdf-loader, one minified IIFE (esbuild)
//   dist/template.html     a complete HTML page, the CSS and the bundle inlined, and one line
//                          `/*NHDYN_DATA*/` that the writer (nhdyn view, tools/make_page.py)
//                          replaces by `window.NHDYN_DATA = {...};`
// Usage: node build.js [--no-minify] [--out DIR]   (DIR: where both go; default dist/ here)
'use strict';
const fs = require('fs');
const path = require('path');
const esbuild = require('esbuild');

const here = __dirname;
const outAt = process.argv.indexOf('--out');
const dist = outAt > 0 && process.argv[outAt + 1] ? path.resolve(process.argv[outAt + 1]) : path.join(here, 'dist');
const minify = !process.argv.includes('--no-minify');
const PLACEHOLDER = '/*NHDYN_DATA*/';

async function main() {
  fs.mkdirSync(dist, { recursive: true });
  const result = await esbuild.build({
    entryPoints: [path.join(here, 'src', 'viewer.js')],
    bundle: true,
    format: 'iife',
    minify,
    target: ['es2020'],
    legalComments: 'none',
    charset: 'utf8',
    write: false,
    logLevel: 'warning',
    metafile: true,
  });
  let js = result.outputFiles[0].text;
  // The bundle goes inside <script>: it must not close it, nor hold the data placeholder.
  js = js.replace(/<\/(script)/gi, '<\\/$1').replace(/<!--/g, '<\\!--');
  if (js.includes(PLACEHOLDER)) throw new Error('the bundle contains the data placeholder');
  fs.writeFileSync(path.join(dist, 'viewer.bundle.js'), js);

  const css = fs.readFileSync(path.join(here, 'src', 'viewer.css'), 'utf8');
  const tpl = fs.readFileSync(path.join(here, 'src', 'template.html'), 'utf8');
  const html = tpl
    .replace('/*NHDYN_CSS*/', () => css.trim())
    .replace('/*NHDYN_BUNDLE*/', () => js.trim());
  const lines = html.split('\n').filter((l) => l.trim() === PLACEHOLDER);
  if (lines.length !== 1 || html.split(PLACEHOLDER).length !== 2) {
    throw new Error('the template must hold exactly one placeholder line ' + PLACEHOLDER);
  }
  fs.writeFileSync(path.join(dist, 'template.html'), html);

  const kb = (n) => (n / 1024).toFixed(1) + ' KiB';
  const inputs = Object.entries(result.metafile.outputs)[0][1].inputs;
  const byPackage = {};
  for (const [file, info] of Object.entries(inputs)) {
    const m = file.match(/node_modules\/((?:@[^/]+\/)?[^/]+)/);
    const key = m ? m[1] : 'src';
    byPackage[key] = (byPackage[key] || 0) + info.bytesInOutput;
  }
  console.log(`${path.join(dist, 'viewer.bundle.js')}  ${kb(Buffer.byteLength(js))} (${minify ? 'minified' : 'not minified'}; ` +
    Object.entries(byPackage).map(([k, v]) => `${k} ${kb(v)}`).join(', ') + ')');
  console.log(`${path.join(dist, 'template.html')}  ${kb(Buffer.byteLength(html))}`);
}

main().catch((e) => { console.error('build.js: ' + (e && e.stack || e)); process.exit(1); });
