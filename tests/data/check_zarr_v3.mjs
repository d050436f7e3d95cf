// Validates the Zarr v3 fixtures of make_ome_zarr_v3.py with zarrita, an independent Zarr v3
// reader (sharding included): every case's level 0 must read back as the numpy array dumped to
// <name>.raw (little-endian, C order), except the cases the manifest marks "zarrita_skip" (index
// at the start of shards, nested sharding, sharding after a transpose: zarrita 0.7.5 reads none
// of them). Transposed arrays come back in stored order with strides; they are compared in C
// order. Usage: node check_zarr_v3.mjs FIXTURE_DIR
// The packages are imported from tests/npm/node_modules by path (they export ES modules only, so
// require.resolve cannot find them). Prints "ok N" on success, exits 1 naming the first mismatch.
import { readFileSync } from "node:fs";
import { fileURLToPath, pathToFileURL } from "node:url";
import path from "node:path";

const here = path.dirname(fileURLToPath(import.meta.url));
const modules = path.join(here, "..", "npm", "node_modules");
const zarr = await import(pathToFileURL(path.join(modules, "zarrita/dist/src/index.js")).href);

/// A read-only zarrita store over a directory. @zarrita/storage's FileSystemStore passes the
/// shard index's BigInt offsets straight to fs.read, which Node rejects; this one converts.
class DirectoryStore {
  constructor(root) {
    this.root = root;
  }
  file(key) {
    return path.join(this.root, key.replace(/^\//, ""));
  }
  async get(key) {
    try {
      return new Uint8Array(readFileSync(this.file(key)));
    } catch (e) {
      if (e.code === "ENOENT") return undefined;
      throw e;
    }
  }
  async getRange(key, range) {
    const all = await this.get(key);
    if (all === undefined) return undefined;
    if ("suffixLength" in range) return all.subarray(all.length - Number(range.suffixLength));
    const offset = Number(range.offset);
    return all.subarray(offset, offset + Number(range.length));
  }
}

/// zarr.get returns a chunk with strides: after a transpose codec its data are in the stored
/// (permuted) order, not C order. Gathers the values into C order.
function cOrder(chunk) {
  const { data, shape, stride } = chunk;
  const c = new Array(shape.length);
  for (let i = shape.length - 1, step = 1; i >= 0; step *= shape[i], --i) c[i] = step;
  if (c.every((s, i) => s === stride[i])) return chunk;
  const out = new data.constructor(data.length);
  const index = new Array(shape.length).fill(0);
  for (let n = 0; n < out.length; ++n) {
    let src = 0;
    for (let d = 0; d < shape.length; ++d) src += index[d] * stride[d];
    out[n] = data[src];
    for (let d = shape.length - 1; d >= 0 && ++index[d] === shape[d]; --d) index[d] = 0;
  }
  return { data: out, shape, stride: c };
}

const dir = process.argv[2];
const manifest = JSON.parse(readFileSync(path.join(dir, "manifest.json"), "utf8"));
let checked = 0, skipped = 0;
for (const c of manifest.cases) {
  if (c.zarrita_skip) {
    ++skipped;  // what zarrita 0.7.5 cannot read (the reason is in the manifest)
    continue;
  }
  const store = new DirectoryStore(path.join(dir, c.name + ".zarr"));
  const group = await zarr.open.v3(zarr.root(store), { kind: "group" });
  if (group.attrs.ome?.version !== "0.5") throw new Error(`${c.name}: attributes.ome.version`);
  const arr = await zarr.open.v3(zarr.root(store).resolve("0"), { kind: "array" });
  const got = cOrder(await zarr.get(arr));
  const bytes = Buffer.from(got.data.buffer, got.data.byteOffset, got.data.byteLength);
  const want = readFileSync(path.join(dir, c.name + ".raw"));
  if (!bytes.equals(want)) {
    let i = 0;
    while (i < want.length && bytes[i] === want[i]) ++i;
    console.error(`${c.name}: zarrita reads other bytes (first difference at byte ${i})`);
    process.exit(1);
  }
  ++checked;
}
console.log(`ok ${checked} (skipped ${skipped} that zarrita cannot read)`);
