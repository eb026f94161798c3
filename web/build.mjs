// Bundle the viewer page's sources (web/src/main.js) into the file the Python package ships:
// src/reliefkit/viewer/static/viewer.js. `node web/build.mjs` from anywhere; the bytes depend
// only on the sources and esbuild's pinned version (tests/viewer/test_bundle.py checks them).
import * as esbuild from 'esbuild';
import { fileURLToPath } from 'node:url';

const root = fileURLToPath(new URL('..', import.meta.url));
await esbuild.build({
  absWorkingDir: root,
  entryPoints: ['web/src/main.js'],
  outfile: process.argv[2] || 'src/reliefkit/viewer/static/viewer.js',
  bundle: true,
  format: 'iife', // a classic script: it runs from file:// too, to say the page needs a server
  target: 'es2022',
  legalComments: 'none',
  logLevel: 'warning',
});
