#!/usr/bin/python3
"""Writes OME-Zarr 0.5 (Zarr v3) test images from the specifications, by hand.

Usage: make_ome_zarr_v3.py OUTDIR

zarr-python on the test machines only writes Zarr v2, so this script writes Zarr v3 itself from
the Zarr v3 core and sharding specifications and OME-NGFF 0.5, sharing no code with resoct's
reader: numpy for arrays, numcodecs for blosc/gzip/zstd, CRC-32C implemented here from its
definition, shard indexes packed by hand. For every case OUTDIR/<name>.zarr is an image group
and OUTDIR/<name>.raw the numpy array (all axes, C order, little-endian); OUTDIR/manifest.json
lists the cases. "pair_v04.zarr" is the same image as "pair_v05.zarr" written as OME-Zarr 0.4
with zarr-python. Hostile variants for the error tests live under OUTDIR/bad/.
Run with Debian's /usr/bin/python3 (python3-numpy, python3-numcodecs, python3-zarr).
"""
import json
import math
import os
import struct
import sys

import numpy as np
from numcodecs import GZip, Blosc, Zstd

NO_ENTRY = 2**64 - 1


def make_crc32c_table():
    table = []
    for i in range(256):
        c = i
        for _ in range(8):
            c = (c >> 1) ^ 0x82F63B78 if c & 1 else c >> 1
        table.append(c)
    return table


CRC32C_TABLE = make_crc32c_table()


def crc32c(data):
    c = 0xFFFFFFFF
    for b in data:
        c = CRC32C_TABLE[(c ^ b) & 0xFF] ^ (c >> 8)
    return c ^ 0xFFFFFFFF


assert crc32c(b"123456789") == 0xE3069283  # the standard check value


def zstd_without_content_size(frame):
    """Rewrites a single zstd frame's header so that it carries no content size (as streaming
    compressors write it): Frame_Content_Size dropped, Single_Segment cleared, a
    Window_Descriptor added (RFC 8878, 3.1.1.1)."""
    assert frame[:4] == b"\x28\xb5\x2f\xfd"
    fhd = frame[4]
    fcs_flag, single, did_flag = fhd >> 6, (fhd >> 5) & 1, fhd & 3
    pos = 5 + (0 if single else 1)
    did_len = [0, 1, 2, 4][did_flag]
    fcs_len = [1 if single else 0, 2, 4, 8][fcs_flag]
    content = int.from_bytes(frame[pos + did_len:pos + did_len + fcs_len], "little")
    if fcs_flag == 1:
        content += 256
    exponent = max(0, math.ceil(math.log2(max(content, 1))) - 10)
    new_fhd = fhd & 0b00011111 & ~0x20
    return (frame[:4] + bytes([new_fhd, exponent << 3]) + frame[pos:pos + did_len] +
            frame[pos + did_len + fcs_len:])


def encode(arr, codecs):
    """Encodes one chunk (an array of exactly the chunk shape) with a codec list."""
    out = arr
    for c in codecs:
        name, conf = c["name"], c.get("configuration", {})
        if name == "transpose":
            out = np.ascontiguousarray(out.transpose(conf["order"]))
        elif name == "bytes":
            order = "<" if conf.get("endian", "little") == "little" else ">"
            out = np.ascontiguousarray(out).astype(out.dtype.newbyteorder(order)).tobytes()
        elif name == "sharding_indexed":
            out = encode_shard(out, conf)
        elif name == "blosc":
            shuffle = {"noshuffle": Blosc.NOSHUFFLE, "shuffle": Blosc.SHUFFLE,
                       "bitshuffle": Blosc.BITSHUFFLE}[conf["shuffle"]]
            typed = np.frombuffer(out, dtype=np.dtype("u%d" % conf["typesize"]))
            out = bytes(Blosc(cname=conf["cname"], clevel=conf["clevel"], shuffle=shuffle,
                              blocksize=conf.get("blocksize", 0)).encode(typed))
        elif name == "gzip":
            out = bytes(GZip(level=conf["level"]).encode(out))
        elif name == "zstd":
            out = bytes(Zstd(level=conf["level"]).encode(out))
            if conf.get("resoct_test_no_content_size"):
                out = zstd_without_content_size(out)
        elif name == "crc32c":
            out = out + struct.pack("<I", crc32c(out))
        else:
            raise ValueError(name)
    return out


def strip_private(codecs):
    """The codec list as zarr.json stores it (without this script's private flags)."""
    out = []
    for c in codecs:
        c = json.loads(json.dumps(c))
        conf = c.get("configuration", {})
        conf.pop("resoct_test_no_content_size", None)
        if "codecs" in conf:
            conf["codecs"] = strip_private(conf["codecs"])
        out.append(c)
    return out


def encode_shard(arr, conf):
    inner = conf["chunk_shape"]
    per = [s // c for s, c in zip(arr.shape, inner)]
    fill = conf["resoct_fill"]
    blobs, entries, offset = [], [], 0
    for idx in np.ndindex(*per):
        sl = tuple(slice(i * c, (i + 1) * c) for i, c in zip(idx, inner))
        sub = arr[sl]
        if np.array_equal(sub, np.full(sub.shape, fill, dtype=sub.dtype), equal_nan=True):
            entries.append((NO_ENTRY, NO_ENTRY))  # empty inner chunk: fill value
            continue
        b = encode(sub, conf["codecs"])
        entries.append((offset, len(b)))
        blobs.append(b)
        offset += len(b)
    index = np.array(entries, dtype=np.uint64).reshape(per + [2])
    index_bytes = len(encode(index, conf["index_codecs"]))
    if conf.get("index_location", "end") == "start":
        index = np.array([(o, n) if o == NO_ENTRY else (o + index_bytes, n) for o, n in entries],
                         dtype=np.uint64).reshape(per + [2])
        return encode(index, conf["index_codecs"]) + b"".join(blobs)
    return b"".join(blobs) + encode(index, conf["index_codecs"])


def with_fill(codecs, fill):
    """Sharding configurations carry the fill value to the encoder (removed from the JSON)."""
    out = json.loads(json.dumps(codecs))
    for c in out:
        if c["name"] == "sharding_indexed":
            c["configuration"]["resoct_fill"] = fill
            c["configuration"]["codecs"] = with_fill(c["configuration"]["codecs"], fill)
    return out


def json_codecs(codecs):
    out = strip_private(codecs)
    for c in out:
        if c["name"] == "sharding_indexed":
            c["configuration"].pop("resoct_fill", None)
            c["configuration"]["codecs"] = json_codecs(c["configuration"]["codecs"])
    return out


DATA_TYPES = {"u1": "uint8", "i1": "int8", "u2": "uint16", "i2": "int16", "u4": "uint32",
              "i4": "int32", "f4": "float32", "f8": "float64"}


def fill_json(v, dtype):
    if np.dtype(dtype).kind == "f":
        if np.isnan(v):
            return "NaN"
        if np.isinf(v):
            return "Infinity" if v > 0 else "-Infinity"
        return float(v)
    return int(v)


def write_array(path, arr, chunk_shape, codecs, fill, names, sep="/", encoding="default",
                skip_empty=True):
    os.makedirs(path, exist_ok=True)
    meta = {
        "zarr_format": 3, "node_type": "array", "shape": list(arr.shape),
        "data_type": DATA_TYPES[arr.dtype.str[1:]],
        "chunk_grid": {"name": "regular", "configuration": {"chunk_shape": list(chunk_shape)}},
        "chunk_key_encoding": {"name": encoding, "configuration": {"separator": sep}},
        "fill_value": fill_json(fill, arr.dtype), "codecs": json_codecs(codecs),
        "attributes": {}, "dimension_names": list(names),
    }
    with open(os.path.join(path, "zarr.json"), "w") as f:
        json.dump(meta, f, indent=1)
    enc_codecs = with_fill(codecs, fill)
    grid = [-(-s // c) for s, c in zip(arr.shape, chunk_shape)]
    for idx in np.ndindex(*grid):
        chunk = np.full(chunk_shape, fill, dtype=arr.dtype)  # border chunks are stored whole
        src = tuple(slice(i * c, min((i + 1) * c, s)) for i, c, s in zip(idx, chunk_shape, arr.shape))
        part = arr[src]
        chunk[tuple(slice(0, n) for n in part.shape)] = part
        if skip_empty and np.array_equal(chunk, np.full(chunk_shape, fill, dtype=arr.dtype),
                                         equal_nan=True):
            continue  # a missing chunk (or shard) is all fill value
        key = sep.join(str(i) for i in idx)
        if encoding == "default":
            key = "c" + sep + key
        file = os.path.join(path, *key.split("/"))
        os.makedirs(os.path.dirname(file), exist_ok=True)
        with open(file, "wb") as f:
            f.write(encode(chunk, enc_codecs))


def axes_json(names):
    kinds = {"t": ("time", "second"), "c": ("channel", None)}
    out = []
    for n in names:
        kind, unit = kinds.get(n, ("space", "micrometer"))
        a = {"name": n, "type": kind}
        if unit:
            a["unit"] = unit
        out.append(a)
    return out


def scales(names, level):
    return [1.0 if a in "tc" else {"z": 2.0, "y": 0.5, "x": 0.5}[a] * 2**level for a in names]


def write_image(outdir, name, arr, names, chunk_shape, codecs, fill=0, levels=1, **kw):
    path = os.path.join(outdir, name + ".zarr")
    os.makedirs(path, exist_ok=True)
    datasets = []
    level = arr
    for lv in range(levels):
        write_array(os.path.join(path, str(lv)), level, chunk_shape, codecs, fill, names, **kw)
        datasets.append({"path": str(lv), "coordinateTransformations": [
            {"type": "scale", "scale": scales(names, lv)}]})
        level = level[tuple(slice(None, None, 2) if a in "zyx" else slice(None) for a in names)]
    group = {"zarr_format": 3, "node_type": "group", "attributes": {"ome": {
        "version": "0.5",
        "multiscales": [{"name": name, "axes": axes_json(names), "datasets": datasets}]}}}
    with open(os.path.join(path, "zarr.json"), "w") as f:
        json.dump(group, f, indent=1)
    arr.astype(arr.dtype.newbyteorder("<")).tofile(os.path.join(outdir, name + ".raw"))
    return {"name": name, "axes": "".join(names), "shape": list(arr.shape), "dtype": arr.dtype.str,
            "levels": levels}


def data(shape, dtype, seed, region=None, fill=0):
    rng = np.random.RandomState(seed)
    idx = np.indices(shape).sum(axis=0).astype(np.float64)
    base = 0.5 + 0.3 * np.sin(idx * 0.37) + 0.2 * rng.random_sample(shape)
    if np.dtype(dtype).kind in "ui":
        info = np.iinfo(np.dtype(dtype))
        span = float(info.max) - float(info.min)
        a = (np.floor(base / 1.01 * span) + float(info.min)).astype(dtype)
    else:
        a = (base * 20.0 - 7.0).astype(np.float32)
        a.flat[::29] = np.nan
        a = a.astype(dtype)
    if region is not None:
        full = np.full(shape, fill, dtype=dtype)
        full[region] = a[region]
        a = full
    return a


def bytes_codec(dtype):
    if np.dtype(dtype).itemsize == 1:
        return {"name": "bytes"}  # endian is optional for one-byte types
    return {"name": "bytes", "configuration": {
        "endian": "big" if np.dtype(dtype).byteorder == ">" else "little"}}


def blosc(cname, shuffle, dtype):
    return {"name": "blosc", "configuration": {"cname": cname, "clevel": 5, "shuffle": shuffle,
                                               "typesize": np.dtype(dtype).itemsize,
                                               "blocksize": 0}}


# Bytes-to-bytes tails of the inner pipelines (the codec under test).
COMPRESSION = {
    "raw": lambda d: [],
    "blosc-lz4-shuffle": lambda d: [blosc("lz4", "shuffle", d)],
    "blosc-lz4hc-noshuffle": lambda d: [blosc("lz4hc", "noshuffle", d)],
    "blosc-zstd-bitshuffle": lambda d: [blosc("zstd", "bitshuffle", d)],
    "blosc-zlib-shuffle": lambda d: [blosc("zlib", "shuffle", d)],
    "blosc-blosclz-bitshuffle": lambda d: [blosc("blosclz", "bitshuffle", d)],
    "gzip": lambda d: [{"name": "gzip", "configuration": {"level": 5}}],
    "zstd": lambda d: [{"name": "zstd", "configuration": {"level": 3, "checksum": False}}],
    "zstd-nosize": lambda d: [{"name": "zstd", "configuration": {
        "level": 3, "checksum": False, "resoct_test_no_content_size": True}}],
    "crc32c": lambda d: [{"name": "crc32c"}],
    "zstd-crc32c": lambda d: [{"name": "zstd", "configuration": {"level": 1, "checksum": False}},
                              {"name": "crc32c"}],
}
DTYPES = ["|u1", "<u2", ">u2", "<f4", ">f4"]
# Signed and wide data types (kept by resoct through its value mapping), in fewer layouts.
TYPED_DTYPES = ["|i1", "<i2", ">i2", "<i4", ">u4", "<f8", ">f8"]
INDEX_CODECS = [{"name": "bytes", "configuration": {"endian": "little"}}, {"name": "crc32c"}]


def sharded(shard_inner, inner, location="end", index_codecs=INDEX_CODECS):
    return [{"name": "sharding_indexed", "configuration": {
        "chunk_shape": list(shard_inner), "codecs": inner, "index_codecs": index_codecs,
        "index_location": location}}]


# (chunk grid shape, codecs from the inner pipeline): the layouts every codec x dtype runs in.
LAYOUTS = {
    "plain": lambda inner: ((4, 3, 5), inner),
    # shards of 2x2x2 inner chunks that do not divide the 11x10x13 array, index at the end
    "shard-end": lambda inner: ((8, 6, 10), sharded((4, 3, 5), inner, "end")),
    "shard-start": lambda inner: ((8, 6, 10), sharded((4, 3, 5), inner, "start")),
    # one shard larger than the array; inner chunks larger than the test's 4^3 bricks
    "one-shard": lambda inner: ((16, 16, 16), sharded((8, 8, 8), inner, "end")),
}
SHAPE = (11, 10, 13)


def write_bad(outdir):
    """Hostile variants of one sharded uint16 image: each breaks one thing."""
    bad = os.path.join(outdir, "bad")
    os.makedirs(bad, exist_ok=True)
    arr = data(SHAPE, "<u2", 99)
    inner = [bytes_codec("<u2")]

    def image(name, codecs=None, chunks=(8, 6, 10), names="zyx", mutate_meta=None):
        case = write_image(bad, name, arr, list("zyx"),
                           chunks, codecs or sharded((4, 3, 5), inner, "end"))
        meta_path = os.path.join(bad, name + ".zarr", "0", "zarr.json")
        if mutate_meta or names != "zyx":
            with open(meta_path) as f:
                meta = json.load(f)
            meta["dimension_names"] = list(names)
            if mutate_meta:
                mutate_meta(meta)
            with open(meta_path, "w") as f:
                json.dump(meta, f)
        return os.path.join(bad, name + ".zarr", "0")

    def patch(path, fn):
        with open(path, "rb") as f:
            b = bytearray(f.read())
        fn(b)
        with open(path, "wb") as f:
            f.write(bytes(b))

    n = 8 * 16 + 4  # index bytes of a 2x2x2 shard with crc32c
    # A flipped bit in the index: the crc32c over the index no longer matches.
    p = image("bad_index_crc")
    patch(os.path.join(p, "c", "0", "0", "0"), lambda b: b.__setitem__(len(b) - n, b[len(b) - n] ^ 1))
    # A shard cut short: shorter than its own index.
    p = image("truncated_index")
    patch(os.path.join(p, "c", "0", "0", "0"), lambda b: b.__delitem__(slice(20, None)))

    def set_entry(b, i, off, nbytes):
        start = len(b) - n + 16 * i
        b[start:start + 16] = struct.pack("<QQ", off, nbytes)
        b[len(b) - 4:] = struct.pack("<I", crc32c(bytes(b[len(b) - n:len(b) - 4])))

    # An entry past the end of the shard (valid checksum).
    p = image("entry_past_end")
    patch(os.path.join(p, "c", "0", "0", "0"), lambda b: set_entry(b, 1, len(b), 100))
    # Two entries over the same bytes.
    p = image("overlapping_entries")
    patch(os.path.join(p, "c", "0", "0", "0"),
          lambda b: set_entry(b, 1, struct.unpack_from("<Q", b, len(b) - n)[0] + 2, 240))
    # An inner chunk that decodes to the wrong size: its entry is 8 bytes short.
    p = image("wrong_inner_size")
    patch(os.path.join(p, "c", "0", "0", "0"),
          lambda b: set_entry(b, 0, 0, struct.unpack_from("<Q", b, len(b) - n + 8)[0] - 8))
    # A crc32c codec on the inner chunks, one data byte flipped.
    p = image("bad_chunk_crc", codecs=sharded((4, 3, 5), inner + [{"name": "crc32c"}], "end"))
    patch(os.path.join(p, "c", "0", "0", "0"), lambda b: b.__setitem__(3, b[3] ^ 0x40))
    image("unknown_codec",
          mutate_meta=lambda m: m["codecs"][0]["configuration"]["codecs"].append(
              {"name": "lzma", "configuration": {}}))
    image("unknown_key_encoding",
          mutate_meta=lambda m: m.__setitem__("chunk_key_encoding", {"name": "morton"}))
    image("dimension_names_disagree", names="zxy")
    image("absurd_shard", mutate_meta=lambda m: (
        m["chunk_grid"]["configuration"].__setitem__("chunk_shape", [2**20, 2**20, 2**20]),
        m["codecs"][0]["configuration"].__setitem__("chunk_shape", [1, 1, 1])))
    image("absurd_chunk", mutate_meta=lambda m: (
        m["chunk_grid"]["configuration"].__setitem__("chunk_shape", [2**20, 2**20, 2**20]),
        m["codecs"][0]["configuration"].__setitem__("chunk_shape", [2**20, 2**20, 2**20])))
    image("unknown_data_type", mutate_meta=lambda m: m.__setitem__("data_type", "complex128"))


def main():
    outdir = sys.argv[1]
    os.makedirs(outdir, exist_ok=True)
    cases = []
    seed = 0
    for cname, tail in COMPRESSION.items():
        for dtype in DTYPES:
            for lname, layout in LAYOUTS.items():
                chunks, codecs = layout([bytes_codec(dtype)] + tail(dtype))
                name = f"{cname}_{dtype[1:]}{'be' if dtype[0] == '>' else ''}_{lname}"
                seed += 1
                case = write_image(outdir, name, data(SHAPE, dtype, seed), list("zyx"), chunks,
                                   codecs, sep="/" if seed % 2 else ".")
                if lname == "shard-start":
                    case["zarrita_skip"] = "reads every shard index from the end"
                cases.append(case)
    for cname in ["blosc-lz4-shuffle", "zstd"]:
        for dtype in TYPED_DTYPES:
            for lname in ["plain", "shard-end"]:
                chunks, codecs = LAYOUTS[lname]([bytes_codec(dtype)] + COMPRESSION[cname](dtype))
                name = f"typed_{cname}_{dtype[1:]}{'be' if dtype[0] == '>' else ''}_{lname}"
                seed += 1
                cases.append(write_image(outdir, name, data(SHAPE, dtype, seed), list("zyx"),
                                         chunks, codecs, sep="/"))
    region = (slice(0, 5), slice(0, 4), slice(2, 9))
    case = write_image(outdir, "typed_fill_i2", data((12, 14, 16), "<i2", 508, region, -1024),
                       list("zyx"), (8, 8, 8), sharded((4, 4, 4), [bytes_codec("<i2")] +
                                                      COMPRESSION["zstd"]("<i2"), "end"), fill=-1024)
    case["fill"] = -1024
    cases.append(case)
    # Nested sharding: shards of 2^3 inner chunks, each itself a shard of 2^3 zstd chunks.
    nested_inner = sharded((2, 2, 2), [bytes_codec("<u2")] + COMPRESSION["zstd"]("<u2"), "end")
    cases.append(write_image(outdir, "nested_u2", data(SHAPE, "<u2", 500), list("zyx"),
                             (8, 8, 8), sharded((4, 4, 4), nested_inner, "end")))
    cases[-1]["zarrita_skip"] = "no nested sharding"
    # Transposes: inside the inner pipeline, and before the sharding codec (whole shards).
    t_inner = [{"name": "transpose", "configuration": {"order": [2, 0, 1]}}, bytes_codec("<f4"),
               {"name": "gzip", "configuration": {"level": 1}}]
    cases.append(write_image(outdir, "transpose_inner_f4", data(SHAPE, "<f4", 501), list("zyx"),
                             (8, 6, 10), sharded((4, 3, 5), t_inner, "end")))
    # The spec's numpy semantics (encoded dimension k = decoded dimension order[k]), as
    # zarr-python and zarrita read them.
    t_plain = [{"name": "transpose", "configuration": {"order": [2, 0, 1]}}, bytes_codec("<u2"),
               {"name": "gzip", "configuration": {"level": 1}}]
    cases.append(write_image(outdir, "transpose_plain_u2", data(SHAPE, "<u2", 507), list("zyx"),
                             (4, 3, 5), t_plain))
    t_outer = [{"name": "transpose", "configuration": {"order": [1, 2, 0]}}] + sharded(
        (3, 5, 4), [bytes_codec(">u2")], "end")
    cases.append(write_image(outdir, "transpose_outer_u2", data(SHAPE, "<u2", 502), list("zyx"),
                             (4, 6, 10), t_outer))
    cases[-1]["zarrita_skip"] = "sharding only as the sole codec"
    # Missing shards and empty inner chunks: only a corner region differs from fill_value.
    for dtype, fill in [("|u1", 7), ("<f4", -2.5), ("<u2", 300)]:
        region = (slice(0, 5), slice(0, 4), slice(2, 9))
        case = write_image(outdir, f"fill_{dtype[1:]}", data((12, 14, 16), dtype, 503, region, fill),
                           list("zyx"), (8, 8, 8), sharded((4, 4, 4), [bytes_codec(dtype)] +
                                                          COMPRESSION["zstd"](dtype), "end"),
                           fill=fill)
        case["fill"] = fill
        cases.append(case)
    # v2 chunk key encoding; channel and time axes.
    cases.append(write_image(outdir, "v2keys_u1", data(SHAPE, "|u1", 504), list("zyx"), (4, 3, 5),
                             [bytes_codec("|u1")], sep=".", encoding="v2"))
    cases.append(write_image(outdir, "tczyx_u2", data((2, 3, 5, 6, 7), "<u2", 505), list("tczyx"),
                             (1, 1, 4, 4, 4), sharded((1, 1, 2, 2, 2), [bytes_codec("<u2")], "end")))
    # The same pyramid as OME-Zarr 0.5 (sharded) and 0.4 (zarr-python, zarr v2).
    pair = data((2, 20, 24, 28), "<u2", 506)
    names = list("czyx")
    cases.append(write_image(outdir, "pair_v05", pair, names, (1, 8, 8, 8),
                             sharded((1, 4, 4, 4), [bytes_codec("<u2")] +
                                     COMPRESSION["blosc-lz4-shuffle"]("<u2"), "end"), levels=3))
    write_v04(outdir, "pair_v04", pair, names, 3)
    write_bad(outdir)
    with open(os.path.join(outdir, "manifest.json"), "w") as f:
        json.dump({"cases": cases}, f, indent=1)


def write_v04(outdir, name, arr, names, levels):
    import zarr  # zarr-python 2: OME-Zarr 0.4 only
    store = zarr.DirectoryStore(os.path.join(outdir, name + ".zarr"))
    root = zarr.group(store=store, overwrite=True)
    datasets = []
    level = arr
    for lv in range(levels):
        z = zarr.create(shape=level.shape, chunks=(1, 5, 5, 5), dtype=level.dtype,
                        compressor=Zstd(level=1), fill_value=0, store=store, path=str(lv))
        z[...] = level
        datasets.append({"path": str(lv), "coordinateTransformations": [
            {"type": "scale", "scale": scales(names, lv)}]})
        level = level[tuple(slice(None, None, 2) if a in "zyx" else slice(None) for a in names)]
    root.attrs.put({"multiscales": [{"version": "0.4", "name": name, "axes": axes_json(names),
                                     "datasets": datasets}]})


if __name__ == "__main__":
    main()
