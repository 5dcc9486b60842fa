/// <reference types="vitest/config" />
import { createHash } from 'node:crypto';
import { mkdirSync, readFileSync, readdirSync, statSync, writeFileSync } from 'node:fs';
import { join, relative, resolve } from 'node:path';
import { promisify } from 'node:util';
import { brotliCompress, constants, gzip } from 'node:zlib';
import { type Plugin, defineConfig } from 'vite';
import { shortHash } from './web/engine/download.ts';

// Cross-origin isolation (COOP + COEP) is what lets onnxruntime-web use SharedArrayBuffer and
// therefore more than one WASM thread. Any static host serving dist/ needs the same two headers;
// without them the page still works, on one thread.
const isolationHeaders = {
  'Cross-Origin-Opener-Policy': 'same-origin',
  'Cross-Origin-Embedder-Policy': 'require-corp',
};

// onnxruntime-web's files (its wasm and the Emscripten loader beside it), imported by path from
// web/engine/wasm.ts: the package's export map does not list them.
const ORT_DIST = resolve('node_modules/onnxruntime-web/dist');
const ORT_WASM = join(ORT_DIST, 'ort-wasm-simd-threaded.wasm');

const brotli = promisify(brotliCompress);
const gz = promisify(gzip);
const COMPRESSIBLE = /\.(js|mjs|css|html|json|svg|wasm|onnx)$/;
const CACHE_DIR = 'node_modules/.cache/duet-precompress';

/**
 * Writes file.br and file.gz beside every compressible file of dist/ over 1 KB, for servers that
 * send precompressed files (scripts/serve.mjs; most static hosts can). Brotli at its best setting
 * takes about 22 s for the 11.2 MB wasm on one core (1.80 MB, against 2.89 MB gzipped), so results
 * are kept in node_modules/.cache by content hash: only the first build pays. Files are compressed
 * in parallel on libuv's thread pool.
 */
function precompress(): Plugin {
  let outDir = 'dist';
  return {
    name: 'duet-precompress',
    apply: 'build',
    configResolved(config) {
      outDir = config.build.outDir;
    },
    async closeBundle() {
      mkdirSync(CACHE_DIR, { recursive: true });
      const files: string[] = [];
      const walk = (dir: string) => {
        for (const name of readdirSync(dir)) {
          const path = join(dir, name);
          if (statSync(path).isDirectory()) walk(path);
          else if (COMPRESSIBLE.test(name) && statSync(path).size > 1024) files.push(path);
        }
      };
      walk(outDir);
      const cached = async (bytes: Buffer, suffix: string, compress: () => Promise<Buffer>) => {
        const key = join(CACHE_DIR, createHash('sha256').update(bytes).digest('hex') + suffix);
        try {
          return readFileSync(key);
        } catch {
          const out = await compress();
          writeFileSync(key, out);
          return out;
        }
      };
      await Promise.all(
        files.map(async (file) => {
          const bytes = readFileSync(file);
          const [br, gzipped] = await Promise.all([
            cached(bytes, '.br', () =>
              brotli(bytes, {
                params: {
                  [constants.BROTLI_PARAM_QUALITY]: 11,
                  [constants.BROTLI_PARAM_LGWIN]: 24,
                  [constants.BROTLI_PARAM_SIZE_HINT]: bytes.length,
                },
              }),
            ),
            cached(bytes, '.gz', () => gz(bytes, { level: 9 })),
          ]);
          // A compressed copy no smaller than the file is no use to anyone.
          if (br.length < bytes.length) writeFileSync(`${file}.br`, br);
          if (gzipped.length < bytes.length) writeFileSync(`${file}.gz`, gzipped);
        }),
      );
      this.info?.(`precompressed ${files.length} files in ${relative(process.cwd(), outDir) || '.'}`);
    },
  };
}

/**
 * The version of the models this build ships (__DUET_MODELS__: the same hash of the manifest's
 * models that web/engine/offline.ts computes), so that a page can tell a manifest of another
 * deployment from its own (a page of one version never dances the models of another). Read from
 * the public folder actually used, which a build may replace (tests/e2e/deploy.mjs does).
 */
function modelsStamp(): Plugin {
  return {
    name: 'duet-models-stamp',
    config(config) {
      const publicDir = resolve(config.root ?? process.cwd(), typeof config.publicDir === 'string' ? config.publicDir : 'public');
      let stamp = '';
      try {
        stamp = shortHash(JSON.stringify(JSON.parse(readFileSync(join(publicDir, 'models', 'manifest.json'), 'utf8')).models));
      } catch {
        // no manifest (yet): the page does not check
      }
      return { define: { __DUET_MODELS__: JSON.stringify(stamp) } };
    },
  };
}

export default defineConfig({
  // Relative asset URLs so dist/ works from any sub-path (GitHub Pages, a folder on a server).
  base: './',
  server: { host: '127.0.0.1', port: 5173, strictPort: false, headers: isolationHeaders },
  preview: { host: '127.0.0.1', port: 4173, strictPort: false, headers: isolationHeaders },
  // onnxruntime-web finds its .wasm/.mjs next to itself via import.meta.url; pre-bundling moves it
  // into .vite/deps and breaks that.
  // Listing the other dependencies up front stops the dev server from discovering them on the
  // first visit and reloading the page (which doubles the first load and confuses the e2e tests).
  optimizeDeps: {
    exclude: ['onnxruntime-web', 'onnxruntime-web-dist'],
    include: ['three', 'three/addons/controls/OrbitControls.js', 'three/examples/jsm/loaders/GLTFLoader.js', 'lil-gui', '@pixiv/three-vrm'],
  },
  // The loading bar's total before the first byte of the wasm arrives (web/engine/wasm.ts).
  define: { __ORT_WASM_BYTES__: JSON.stringify(statSync(ORT_WASM).size) },
  resolve: { alias: { 'onnxruntime-web-dist': ORT_DIST } },
  build: { target: 'es2022' },
  plugins: [precompress(), modelsStamp()],
  test: {
    include: ['tests/web/**/*.test.ts'],
    // No test is about speed (that is `npm run bench`): vitest's 5 s default would fail the
    // fixture-heavy tests on a machine busy with other work, so they wait as long as they need.
    testTimeout: 600_000,
    hookTimeout: 600_000,
  },
});
