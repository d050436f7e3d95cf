#!/usr/bin/python3
"""Writes the OME-Zarr test images with the reference implementation (zarr-python, numcodecs).

Usage: make_ome_zarr.py OUTDIR

For every case OUTDIR/<name>.zarr is an OME-Zarr image group and OUTDIR/<name>.raw holds the
same numpy array (all axes, C order) as little-endian bytes of its decoded type, so the C++
test compares the reader voxel by voxel against numpy. OUTDIR/manifest.json lists the cases.
Run with Debian's /usr/bin/python3 (python3-zarr, python3-numcodecs, python3-numpy).
"""
import json
import os
import sys

import numpy as np
import zarr
from numcodecs import GZip, LZ4, Blosc, Zlib, Zstd

COMPRESSORS = {
    "blosc-lz4-shuffle": lambda: Blosc(cname="lz4", clevel=5, shuffle=Blosc.SHUFFLE),
    "blosc-zstd-bitshuffle": lambda: Blosc(cname="zstd", clevel=3, shuffle=Blosc.BITSHUFFLE),
    "blosc-zlib-noshuffle": lambda: Blosc(cname="zlib", clevel=4, shuffle=Blosc.NOSHUFFLE),
    "lz4": lambda: LZ4(acceleration=1),
    "zstd": lambda: Zstd(level=3),
    "zlib": lambda: Zlib(level=5),
    "gzip": lambda: GZip(level=5),
    "none": lambda: None,
}
DTYPES = ["|u1", "<u2", ">u2", "<f4", ">f4"]
TYPED_DTYPES = ["|i1", "<i2", ">i2", "<i4", ">u4", "<f8", ">f8"]
# Axis subsets and their extents (t and c small, spatial extents not multiples of the chunks).
AXES = {
    "zyx": {"z": 11, "y": 10, "x": 13},
    "czyx": {"c": 3, "z": 9, "y": 10, "x": 7},
    "tczyx": {"t": 2, "c": 2, "z": 7, "y": 6, "x": 9},
    "tzyx": {"t": 3, "z": 6, "y": 7, "x": 8},
    "cyx": {"c": 2, "y": 12, "x": 11},
}
# Chunkings: small irregular chunks (many border chunks), and one chunk larger than the array.
CHUNKINGS = {
    "small": {"t": 1, "c": 1, "z": 4, "y": 3, "x": 5},
    "large": {"t": 2, "c": 4, "z": 16, "y": 16, "x": 16},
}
UNITS = {"z": "micrometer", "y": "micrometer", "x": "micrometer"}


def data(shape, dtype, seed):
    rng = np.random.RandomState(seed)
    idx = np.indices(shape).sum(axis=0).astype(np.float64)
    base = 0.5 + 0.3 * np.sin(idx * 0.37) + 0.2 * rng.random_sample(shape)
    kind = np.dtype(dtype).kind
    if kind in "ui":
        info = np.iinfo(np.dtype(dtype))
        a = np.floor(base / 1.01 * (float(info.max) - float(info.min))) + float(info.min)
        return a.astype(dtype)
    a = (base * 20.0 - 7.0).astype(np.float32)
    a.flat[:: 29] = np.nan
    return a.astype(dtype)


def axes_json(names):
    out = []
    for n in names:
        if n == "t":
            out.append({"name": "t", "type": "time", "unit": "second"})
        elif n == "c":
            out.append({"name": "c", "type": "channel"})
        else:
            out.append({"name": n, "type": "space", "unit": UNITS[n]})
    return out


def write_raw(path, arr):
    le = arr.astype(arr.dtype.newbyteorder("<"))
    le.tofile(path)


def write_case(outdir, name, names, shape, chunks, dtype, comp, sep, levels=1, fill=0,
               region=None, omero=None, seed=0, translation=None):
    """levels > 1 writes coarser datasets downsampled 2x along every spatial axis with resoct's
    rule (mean of the existing children, integers round half up, NaN ignored)."""
    path = os.path.join(outdir, name + ".zarr")
    store = zarr.DirectoryStore(path)
    root = zarr.group(store=store, overwrite=True)
    arr = data(shape, dtype, seed)
    if region is not None:
        full = np.full(shape, fill, dtype=dtype)
        full[region] = arr[region]
        arr = full
    datasets = []
    level = arr
    scale = [1.0] * len(names)
    for n, a in enumerate(names):
        if a in "zyx":
            scale[n] = {"z": 2.0, "y": 0.5, "x": 0.5}[a]
    for lv in range(levels):
        z = zarr.create(shape=level.shape, chunks=chunks, dtype=dtype, compressor=comp(),
                        fill_value=fill, store=store, path=str(lv), dimension_separator=sep,
                        overwrite=True)
        if region is not None and lv == 0:
            z[region] = level[region]
        else:
            z[...] = level
        datasets.append({"path": str(lv), "coordinateTransformations": [
            {"type": "scale", "scale": list(scale)},
            {"type": "translation", "translation": translation or [0.0] * len(names)}]})
        if lv + 1 < levels:
            level = downsample(level, names)
            scale = [s * 2 if a in "zyx" else s for s, a in zip(scale, names)]
    attrs = {"multiscales": [{"version": "0.4", "name": name, "axes": axes_json(names),
                              "datasets": datasets}]}
    if omero is not None:
        attrs["omero"] = omero
    root.attrs.put(attrs)
    write_raw(os.path.join(outdir, name + ".raw"), arr)
    return {"name": name, "axes": "".join(names), "shape": list(shape), "dtype": dtype,
            "chunks": list(chunks), "separator": sep, "levels": levels, "fill": fill,
            "scale": [1.0 if a in "tc" else {"z": 2.0, "y": 0.5, "x": 0.5}[a] for a in names]}


def downsample(a, names):
    """One coarser level along every spatial axis of extent > 1, by resoct's rule: the mean
    over the whole footprint (up to 2x2x2 fine voxels, only those that exist), NaN left out
    (all NaN gives NaN), integers rounded half up."""
    f = a.astype(np.float64)
    pair_axes = []
    shape = []
    for n, ax in enumerate(names):
        if ax in "zyx" and f.shape[n] > 1:
            if f.shape[n] % 2:
                pad = [(0, 0)] * f.ndim
                pad[n] = (0, 1)
                f = np.pad(f, pad, constant_values=np.nan)
            shape += [f.shape[n] // 2, 2]
            pair_axes.append(len(shape) - 1)
        else:
            shape.append(f.shape[n])
    f = f.reshape(shape)
    valid = ~np.isnan(f)
    total = np.where(valid, f, 0.0).sum(axis=tuple(pair_axes))
    count = valid.sum(axis=tuple(pair_axes))
    if np.dtype(a.dtype).kind == "u":
        return np.floor((total + count // 2) / count).astype(a.dtype)
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = np.where(count > 0, total / np.maximum(count, 1), np.nan)
    return mean.astype(np.float32).astype(a.dtype)


def main():
    outdir = sys.argv[1]
    os.makedirs(outdir, exist_ok=True)
    cases = []
    i = 0
    for cname, comp in COMPRESSORS.items():
        for dtype in DTYPES:
            for chunking, cdef in CHUNKINGS.items():
                for axes, extents in AXES.items():
                    names = list(axes)
                    shape = tuple(extents[a] for a in names)
                    chunks = tuple(cdef[a] for a in names)
                    sep = "/" if i % 2 else "."
                    name = f"{cname}_{dtype[0] == '>' and 'be' or 'le'}{dtype[1:]}_{chunking}_{axes}"
                    cases.append(write_case(outdir, name, names, shape, chunks, dtype, comp, sep,
                                            seed=i))
                    i += 1
    # Signed and wide dtypes, kept by resoct through its value mapping (i1/i2 with an offset,
    # u4/i4/f8 as f32): both byte orders, two compressors, a missing-chunk fill of the signed
    # range and an omero window in the file's units.
    for cname in ["blosc-lz4-shuffle", "zlib"]:
        for dtype in TYPED_DTYPES:
            names = list("czyx")
            name = f"typed_{cname}_{dtype[0] == '>' and 'be' or 'le'}{dtype[1:]}"
            cases.append(write_case(outdir, name, names, (2, 9, 10, 7), (1, 4, 3, 5), dtype,
                                    COMPRESSORS[cname], "/", seed=i))
            i += 1
    ct_window = {"channels": [{"label": "CT", "color": "FFFFFF", "active": True,
                               "window": {"start": -1000, "end": 2000, "min": -32768,
                                          "max": 32767}}]}
    cases.append(write_case(outdir, "typed_fill_i2", list("zyx"), (12, 14, 16), (4, 4, 4), "<i2",
                            COMPRESSORS["zstd"], "/", fill=-1024,
                            region=(slice(0, 5), slice(0, 6), slice(2, 9)), omero=ct_window,
                            seed=404))
    # Multiscales: three stored levels (2x per spatial axis each), coarser ones built by resoct.
    for dtype in ["<u2", ">f4"]:
        names = list("czyx")
        cases.append(write_case(outdir, f"pyramid_{dtype[1:]}", names, (2, 30, 36, 40),
                                (1, 8, 8, 8), dtype, COMPRESSORS["blosc-lz4-shuffle"], ".",
                                levels=3, seed=101))
    # Missing chunks: only a corner region is written, everything else is fill_value.
    for dtype, fill in [("|u1", 7), ("<f4", -2.5)]:
        names = list("zyx")
        cases.append(write_case(outdir, f"fill_{dtype[1:]}", names, (12, 14, 16), (4, 4, 4),
                                dtype, COMPRESSORS["zstd"], "/", fill=fill,
                                region=(slice(0, 5), slice(0, 6), slice(2, 9)), seed=202))
    # omero windows become the channel value ranges.
    omero = {"channels": [{"label": "DAPI", "color": "0000FF", "active": True,
                           "window": {"start": 100, "end": 4000, "min": 0, "max": 65535}},
                          {"label": "GFP", "color": "00FF00", "active": True,
                           "window": {"start": 0, "end": 65535, "min": 0, "max": 65535}}]}
    cases.append(write_case(outdir, "omero", list("czyx"), (2, 5, 6, 7), (1, 5, 6, 7), "<u2",
                            COMPRESSORS["zlib"], ".", omero=omero, seed=303,
                            translation=[0.0, 1.5, -2.0, 3.0]))
    with open(os.path.join(outdir, "manifest.json"), "w") as f:
        json.dump({"cases": cases}, f, indent=1)


if __name__ == "__main__":
    main()
