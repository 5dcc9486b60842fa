// A small static server for dist/ (no dependencies): sends the precompressed .br / .gz files the
// build writes (vite.config.ts, precompress) to browsers that accept them, with the COOP/COEP
// headers that give onnxruntime its threads, and the right MIME types (application/wasm lets the
// browser compile the wasm while it streams).
//
//   npm run build && node scripts/serve.mjs [--port 8080] [--base /duet/] [--dir dist] [--no-isolation]
//
// Also imported by scripts/bench.mjs and the e2e tests: serve({ dir, port, base }) -> { url, stop }.

import { createReadStream, statSync } from 'node:fs';
import { createServer } from 'node:http';
import { extname, join, normalize, resolve, sep } from 'node:path';
import { fileURLToPath } from 'node:url';

const TYPES = {
  '.html': 'text/html; charset=utf-8',
  '.js': 'text/javascript; charset=utf-8',
  '.mjs': 'text/javascript; charset=utf-8',
  '.css': 'text/css; charset=utf-8',
  '.json': 'application/json; charset=utf-8',
  '.wasm': 'application/wasm',
  '.onnx': 'application/octet-stream',
  '.svg': 'image/svg+xml',
  '.png': 'image/png',
  '.ico': 'image/x-icon',
  '.txt': 'text/plain; charset=utf-8',
  '.bvh': 'text/plain; charset=utf-8',
};

const ISOLATION = {
  'Cross-Origin-Opener-Policy': 'same-origin',
  'Cross-Origin-Embedder-Policy': 'require-corp',
};

function stat(path) {
  try {
    const s = statSync(path);
    return s.isFile() ? s : null;
  } catch {
    return null;
  }
}

/** Which encodings the request accepts, best first (q=0 excluded). */
function accepted(header = '') {
  const ok = new Set();
  for (const part of header.split(',')) {
    const [name, ...params] = part.trim().toLowerCase().split(';');
    const q = params.map((p) => p.trim()).find((p) => p.startsWith('q='));
    if (name && !(q && Number(q.slice(2)) === 0)) ok.add(name);
  }
  return ['br', 'gzip'].filter((e) => ok.has(e) || ok.has('*'));
}

export function handler({ dir = 'dist', base = '/', isolation = true } = {}) {
  const root = resolve(dir);
  const prefix = base.endsWith('/') ? base : `${base}/`;
  return (request, response) => {
    let path;
    try {
      path = decodeURIComponent(new URL(request.url, 'http://localhost').pathname);
    } catch {
      return response.writeHead(400).end();
    }
    if (request.method !== 'GET' && request.method !== 'HEAD') return response.writeHead(405, { Allow: 'GET, HEAD' }).end();
    if (path === prefix.slice(0, -1)) return response.writeHead(301, { Location: prefix }).end();
    if (!path.startsWith(prefix)) return response.writeHead(404).end('not found');
    let file = normalize(join(root, path.slice(prefix.length)));
    if (file !== root && !file.startsWith(root + sep)) return response.writeHead(403).end();
    if (path.endsWith('/')) file = join(file, 'index.html');
    const info = stat(file);
    if (!info) return response.writeHead(404, { 'Content-Type': 'text/plain' }).end('not found');

    const headers = {
      'Content-Type': TYPES[extname(file)] ?? 'application/octet-stream',
      Vary: 'Accept-Encoding',
      // Hashed build assets never change; everything else is revalidated (a cheap 304).
      'Cache-Control': /[\\/]assets[\\/]/.test(file) ? 'public, max-age=31536000, immutable' : 'no-cache',
      'Cross-Origin-Resource-Policy': 'same-origin',
      ...(isolation ? ISOLATION : {}),
    };
    if (path.endsWith('/sw.js')) headers['Cache-Control'] = 'no-cache';
    let body = file;
    let size = info.size;
    for (const encoding of accepted(request.headers['accept-encoding'])) {
      const variant = stat(`${file}.${encoding === 'br' ? 'br' : 'gz'}`);
      // A compressed copy older than the file is of an earlier version of it (the file was
      // rebuilt or edited without compressing again): never send it in the file's place.
      if (variant && variant.mtimeMs >= info.mtimeMs) {
        body = `${file}.${encoding === 'br' ? 'br' : 'gz'}`;
        size = variant.size;
        headers['Content-Encoding'] = encoding;
        break;
      }
    }
    const etag = `"${info.size.toString(36)}-${Math.floor(info.mtimeMs).toString(36)}${headers['Content-Encoding'] ? `-${headers['Content-Encoding']}` : ''}"`;
    headers.ETag = etag;
    if (request.headers['if-none-match'] === etag) return response.writeHead(304, headers).end();
    headers['Content-Length'] = size;
    response.writeHead(200, headers);
    if (request.method === 'HEAD') return response.end();
    createReadStream(body).pipe(response);
  };
}

/** Start serving; resolves to { url, port, stop }. Port 0 picks a free one. */
export function serve({ dir = 'dist', port = 0, host = '127.0.0.1', base = '/', isolation = true } = {}) {
  const server = createServer(handler({ dir, base, isolation }));
  return new Promise((done, fail) => {
    server.once('error', fail);
    server.listen(port, host, () => {
      const url = `http://${host}:${server.address().port}${base.endsWith('/') ? base : `${base}/`}`;
      done({ url, port: server.address().port, stop: () => new Promise((closed) => { server.closeAllConnections?.(); server.close(() => closed()); }) });
    });
  });
}

if (process.argv[1] && resolve(process.argv[1]) === fileURLToPath(import.meta.url)) {
  const args = process.argv.slice(2);
  const option = (name, fallback) => {
    const i = args.indexOf(`--${name}`);
    return i >= 0 ? args[i + 1] : fallback;
  };
  const { url } = await serve({
    dir: option('dir', 'dist'),
    port: Number(option('port', 8080)),
    host: option('host', '127.0.0.1'),
    base: option('base', '/'),
    isolation: !args.includes('--no-isolation'),
  });
  console.log(`serving ${option('dir', 'dist')} at ${url}`);
}
