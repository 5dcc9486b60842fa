/// <reference types="vitest/config" />
import { defineConfig } from 'vite';

// Cross-origin isolation (COOP + COEP) is what lets onnxruntime-web use SharedArrayBuffer and
// therefore more than one WASM thread. Any static host serving dist/ needs the same two headers;
// without them the page still works, on one thread.
const isolationHeaders = {
  'Cross-Origin-Opener-Policy': 'same-origin',
  'Cross-Origin-Embedder-Policy': 'require-corp',
};

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
    exclude: ['onnxruntime-web'],
    include: ['three', 'three/addons/controls/OrbitControls.js', 'lil-gui'],
  },
  build: { target: 'es2022' },
  test: {
    include: ['tests/web/**/*.test.ts'],
  },
});
