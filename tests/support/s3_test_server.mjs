// An S3-compatible server on loopback for the object-store tests (started through
// tests/support/s3_test_server.hpp): s3rver from tests/npm/node_modules (installed by
// scripts/install-test-tools.sh) on an ephemeral port, its data in a fresh temporary directory.
//
//   node s3_test_server.mjs [--token TOKEN] BUCKET[=DIR]...
//
// Creates each BUCKET and uploads every file below DIR (dot files included) under its path
// relative to DIR, then prints "PORT n" on stdout. Exits, removing its data, when stdin closes,
// so it dies with the test process even when that is killed.
//
// s3rver accepts any well-formed SigV4 signature by a known key (it only checks signatures of
// the older V2 scheme). A client that signs wrongly would pass unnoticed, so a middleware in
// front of s3rver verifies every "AWS4-HMAC-SHA256" Authorization header itself (AWS Signature
// Version 4, header form, as specified in the AWS S3 API reference) and answers 403
// SignatureDoesNotMatch on a mismatch. With --token, a signed request must also carry the
// session token as a signed x-amz-security-token header (403 InvalidToken otherwise).
// Unsigned requests pass: s3rver serves them as anonymous access.

import { createHash, createHmac } from 'node:crypto';
import { createRequire } from 'node:module';
import { mkdtempSync, readdirSync, readFileSync, rmSync, statSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join, relative, sep } from 'node:path';

const require = createRequire(new URL('../npm/package.json', import.meta.url));
const S3rver = require('s3rver');

const ACCOUNTS = { S3RVER: 'S3RVER' };  // s3rver's built-in account: access key id -> secret

const args = process.argv.slice(2);
let token = null;
const buckets = [];
for (let i = 0; i < args.length; ++i) {
  if (args[i] === '--token') {
    token = args[++i];
  } else {
    const eq = args[i].indexOf('=');
    buckets.push(eq < 0 ? { name: args[i], dir: null }
                        : { name: args[i].slice(0, eq), dir: args[i].slice(eq + 1) || null });
  }
}

function filesBelow(dir) {
  const out = [];
  for (const name of readdirSync(dir)) {
    const path = join(dir, name);
    if (statSync(path).isDirectory()) out.push(...filesBelow(path));
    else out.push(path);
  }
  return out;
}

const hmac = (key, text) => createHmac('sha256', key).update(text).digest();
const sha256 = text => createHash('sha256').update(text).digest('hex');

function s3Error(ctx, status, code, message) {
  ctx.status = status;
  ctx.type = 'application/xml';
  ctx.set('x-amz-error-code', code);
  ctx.body = `<?xml version="1.0" encoding="UTF-8"?>\n<Error><Code>${code}</Code>` +
             `<Message>${message}</Message></Error>`;
}

/// Recomputes the request's SigV4 signature from the secret of the key it names.
async function verifySigV4(ctx, next) {
  const auth = ctx.get('authorization');
  if (!auth.startsWith('AWS4-HMAC-SHA256 ')) return next();
  const fields = Object.fromEntries(auth.slice(17).split(',').map(f => {
    const eq = f.indexOf('=');
    return [f.slice(0, eq).trim(), f.slice(eq + 1).trim()];
  }));
  const [keyId, date, region, service, terminator] = (fields.Credential || '').split('/');
  const secret = ACCOUNTS[keyId];
  if (secret === undefined) return next();  // s3rver answers InvalidAccessKeyId
  const signed = (fields.SignedHeaders || '').split(';');
  const rawUrl = ctx.req.url;
  const q = rawUrl.indexOf('?');
  const query = q < 0 ? '' : rawUrl.slice(q + 1).split('&').filter(Boolean).sort().join('&');
  const canonical = [
    ctx.method,
    q < 0 ? rawUrl : rawUrl.slice(0, q),
    query,
    signed.map(h => `${h}:${String(ctx.get(h)).trim().replace(/ +/g, ' ')}\n`).join(''),
    signed.join(';'),
    ctx.get('x-amz-content-sha256'),
  ].join('\n');
  const scope = [date, region, service, terminator].join('/');
  const toSign = ['AWS4-HMAC-SHA256', ctx.get('x-amz-date'), scope, sha256(canonical)].join('\n');
  let key = hmac('AWS4' + secret, date);
  for (const part of [region, service, terminator]) key = hmac(key, part);
  if (hmac(key, toSign).toString('hex') !== fields.Signature) {
    return s3Error(ctx, 403, 'SignatureDoesNotMatch',
                   'The request signature we calculated does not match the signature you provided.');
  }
  if (token !== null &&
      (!signed.includes('x-amz-security-token') || ctx.get('x-amz-security-token') !== token)) {
    return s3Error(ctx, 403, 'InvalidToken', 'The provided token is malformed or otherwise invalid.');
  }
  return next();
}

const directory = mkdtempSync(join(tmpdir(), 'resoct-s3rver-'));
const server = new S3rver({
  address: '127.0.0.1',
  port: 0,
  silent: true,
  directory,
  configureBuckets: buckets.map(b => ({ name: b.name, configs: [] })),
});
server.middleware.unshift(verifySigV4);  // Koa composes its middleware when it starts listening

// The data is removed synchronously before exiting: the test process closes stdin and then
// sends SIGTERM at once, so there is no time to wait for open connections to close.
function shutdown(code) {
  rmSync(directory, { recursive: true, force: true });
  process.exit(code);
}

process.stdin.on('end', () => shutdown(0));
process.stdin.on('close', () => shutdown(0));
process.on('SIGTERM', () => shutdown(0));
process.on('SIGINT', () => shutdown(0));
process.stdin.resume();

try {
  const { port } = await server.run();
  // Uploads go through the server's own PUT (unsigned, so anonymous), like any client's would.
  for (const b of buckets) {
    if (b.dir === null) continue;
    for (const file of filesBelow(b.dir)) {
      const key = relative(b.dir, file).split(sep).map(encodeURIComponent).join('/');
      const r = await fetch(`http://127.0.0.1:${port}/${b.name}/${key}`, {
        method: 'PUT',
        body: readFileSync(file),
      });
      if (!r.ok) throw new Error(`upload of ${file} failed: HTTP ${r.status}`);
    }
  }
  process.stdout.write(`PORT ${port}\n`);
} catch (e) {
  process.stdout.write(`ERROR ${e.message}\n`);
  shutdown(1);
}
