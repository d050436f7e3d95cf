#!/usr/bin/python3
"""Peer comparison: VTK's vtkFixedPointVolumeRayCastMapper against resoct-render (CPU backend)
on the same sphere volume, camera and transfer function.

    xvfb-run -a /usr/bin/python3 bench/peers/vtk_raycast.py   (re-runs itself under xvfb-run
                                                                when DISPLAY is not set)

Both render procedural:sphere at --size³ (float32, v = max(0, 1 - r / R) at voxel centres, the
formula of src/core/sources/procedural/analytic.cpp SphereField evaluated in double and rounded to float
once, as ProceduralSource stores f32 voxels; with --type u8, round(255 v) as unsigned bytes, which
resoct reads from a brick store made by resoct-convert) with the camera, viewport and transfer function of
examples/scenes/sphere.json, on --threads threads. VTK: trilinear interpolation, no shading,
sample distance and scalar-opacity unit distance one voxel (resoct's TF alpha is the opacity of
one voxel), no automatic sample-distance adjustment, one ray per pixel. resoct: resoct-render
--backend cpu from a cold cache until converged, then --frames steady frames (OMP_NUM_THREADS
sets the CPU backend's render threads, --threads its loader threads).

Writes bench/results/peer_vtk.json (through a temporary file): ms/frame mean and median (wall
and CPU time of the process) for both, the mean and largest absolute RGB difference of the two
images in 1/255 units, the machine load, and where the images are (--work, default
build/peer_vtk). --verify-raw FILE compares the generated volume bitwise with level-0 voxels
written by resoct itself (RESOCT_LIMIT_OUT=DIR build/release/bench/resoct_bench_limit
--benchmark_filter='scene:0/impl:0' writes DIR/sphere_256x256x256_f32.raw).
"""

import argparse
import datetime
import hashlib
import json
import os
import platform
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))


def parse_args():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--size", type=int, default=256, help="sphere extent per axis (voxels)")
    p.add_argument("--type", choices=["f32", "u8"], default="f32",
                   help="voxel type: f32 (procedural:sphere itself) or u8 (the sphere rounded to "
                        "round(255 v), converted to a brick store with resoct-convert; the "
                        "issue's volume)")
    p.add_argument("--resoct-convert",
                   default=os.path.join(ROOT, "build/release/examples/resoct-convert"))
    p.add_argument("--scene", default=os.path.join(ROOT, "examples/scenes/sphere.json"))
    p.add_argument("--frames", type=int, default=10, help="timed frames (each renderer)")
    p.add_argument("--warmup", type=int, default=2, help="untimed VTK frames first")
    p.add_argument("--threads", type=int, default=2)
    p.add_argument("--resoct-render",
                   default=os.path.join(ROOT, "build/release/examples/resoct-render"))
    p.add_argument("--work", default=os.path.join(ROOT, "build/peer_vtk"), help="images, stats")
    p.add_argument("--out", default=os.path.join(ROOT, "bench/results/peer_vtk.json"))
    p.add_argument("--verify-raw",
                   help="resoct's level-0 voxels of the same sphere (f32, x fastest)")
    p.add_argument("--no-xvfb", action="store_true", help="do not re-run under xvfb-run")
    return p.parse_args()


def sphere_volume(n):
    """procedural:sphere:NxNxN exactly: SphereField at voxel centres, double, rounded to f32."""
    c = np.arange(n, dtype=np.float64) + 0.5
    centre = 0.5 * n  # extent * 0.5
    radius = 0.5 * n  # half the smallest extent
    dx = c - centre
    # glm::length(v) = sqrt(x*x + y*y + z*z), summed in that order; array index [z, y, x].
    d2 = (dx[None, None, :] * dx[None, None, :] + dx[None, :, None] * dx[None, :, None]) + (
        dx[:, None, None] * dx[:, None, None])
    v = np.maximum(0.0, 1.0 - np.sqrt(d2) / radius)
    return v.astype(np.float32)


def load_avg():
    with open("/proc/loadavg") as f:
        return [float(x) for x in f.read().split()[:3]]


def proc_cpu_seconds(pid):
    """utime + stime of a live process (its threads included), in seconds."""
    with open(f"/proc/{pid}/stat") as f:
        fields = f.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def rel(path):
    """A path relative to the repository when it lies inside it (portable JSON)."""
    path = os.path.abspath(path)
    return os.path.relpath(path, ROOT) if path.startswith(ROOT + os.sep) else path


def stats_ms(values):
    return {"mean": statistics.fmean(values), "median": statistics.median(values),
            "min": min(values), "max": max(values)}


def render_vtk(vol, scene, args, png):
    import vtk
    from vtk.util import numpy_support

    n = vol.shape[0]
    h = 1.0 / n  # voxel size in box units (cube: the longest axis spans [0, 1])
    vtk.vtkMultiThreader.SetGlobalMaximumNumberOfThreads(args.threads)
    vtk.vtkMultiThreader.SetGlobalDefaultNumberOfThreads(args.threads)

    image = vtk.vtkImageData()
    image.SetDimensions(n, n, n)
    image.SetSpacing(h, h, h)
    image.SetOrigin(0.5 * h, 0.5 * h, 0.5 * h)  # VTK points are voxel centres: (i + 0.5) / n
    u8 = vol.dtype == np.uint8
    scalars = numpy_support.numpy_to_vtk(vol.ravel(order="C"), deep=True,
                                         array_type=vtk.VTK_UNSIGNED_CHAR if u8 else vtk.VTK_FLOAT)
    image.GetPointData().SetScalars(scalars)

    channel = scene["channels"][0]
    colour = vtk.vtkColorTransferFunction()
    opacity = vtk.vtkPiecewiseFunction()
    # The TF's points are normalized values: resoct maps f32 [0, 1] and u8 [0, 255] (the type's
    # range, resoct-convert's default for raw u8) to [0, 1].
    scale = 255.0 if u8 else 1.0
    for value, r, g, b, a in channel["tf"]:
        colour.AddRGBPoint(value * scale, r, g, b)
        opacity.AddPoint(value * scale, a)

    prop = vtk.vtkVolumeProperty()
    prop.SetColor(colour)
    prop.SetScalarOpacity(opacity)
    prop.SetInterpolationTypeToLinear()
    prop.ShadeOff()
    prop.SetScalarOpacityUnitDistance(h)

    mapper = vtk.vtkFixedPointVolumeRayCastMapper()
    mapper.SetInputData(image)
    mapper.SetBlendModeToComposite()
    mapper.AutoAdjustSampleDistancesOff()
    mapper.LockSampleDistanceToInputSpacingOff()
    mapper.SetSampleDistance(h)
    mapper.SetInteractiveSampleDistance(h)
    mapper.SetImageSampleDistance(1.0)
    mapper.SetMinimumImageSampleDistance(1.0)
    mapper.SetMaximumImageSampleDistance(1.0)
    mapper.SetNumberOfThreads(args.threads)

    volume = vtk.vtkVolume()
    volume.SetMapper(mapper)
    volume.SetProperty(prop)

    renderer = vtk.vtkRenderer()
    renderer.AddVolume(volume)
    bg = scene.get("background", [0, 0, 0, 1])
    renderer.SetBackground(bg[0], bg[1], bg[2])
    cam = scene["camera"]
    camera = renderer.GetActiveCamera()
    camera.SetPosition(*cam["eye"])
    camera.SetFocalPoint(*cam["target"])
    camera.SetViewUp(*cam.get("up", [0, 1, 0]))
    camera.SetViewAngle(cam.get("fov_deg", 40))  # vertical, like resoct's fov_deg
    renderer.ResetCameraClippingRange()

    window = vtk.vtkRenderWindow()
    window.SetOffScreenRendering(1)
    window.SetSize(scene["viewport"]["width"], scene["viewport"]["height"])
    window.AddRenderer(renderer)

    for _ in range(args.warmup):
        window.Render()
    wall, cpu = [], []
    for _ in range(args.frames):
        camera.Modified()  # the mapper casts every ray again in every Render()
        c0, w0 = time.process_time(), time.perf_counter()
        window.Render()
        w1, c1 = time.perf_counter(), time.process_time()
        wall.append((w1 - w0) * 1e3)
        cpu.append((c1 - c0) * 1e3)

    grab = vtk.vtkWindowToImageFilter()
    grab.SetInput(window)
    grab.SetInputBufferTypeToRGB()
    grab.ReadFrontBufferOff()
    grab.Update()
    writer = vtk.vtkPNGWriter()
    writer.SetFileName(png)
    writer.SetInputConnection(grab.GetOutputPort())
    writer.Write()
    return {
        "vtk_version": vtk.vtkVersion.GetVTKVersion(),
        "mapper": "vtkFixedPointVolumeRayCastMapper",
        "threads": mapper.GetNumberOfThreads(),
        "sample_distance": h,
        "scalar_opacity_unit_distance": h,
        "interpolation": "linear",
        "frames": args.frames,
        "warmup_frames": args.warmup,
        "ms_frame": stats_ms(wall),
        "cpu_ms_frame": stats_ms(cpu),
        "png": rel(png),
    }


def render_resoct(args, spec, png, stats_path):
    """Cold cache to convergence, then args.frames steady frames; CPU time of those frames from
    /proc while the process runs (sampled as each frame's line appears on stderr)."""
    cmd = [args.resoct_render, "--volume", spec, "--scene", args.scene, "--backend", "cpu",
           "--mode", "residency", "--converge", "--steady-frames", str(args.frames),
           "--threads", str(args.threads), "--out", png, "--stats", stats_path]
    env = dict(os.environ, OMP_NUM_THREADS=str(args.threads))
    proc = subprocess.Popen(cmd, stderr=subprocess.PIPE, text=True, env=env)
    lines = []  # (frame line, process CPU seconds right after it)
    for line in proc.stderr:
        if line.startswith("frame "):
            try:
                lines.append((line, proc_cpu_seconds(proc.pid)))
            except OSError:
                lines.append((line, None))
        else:
            sys.stderr.write(line)
    if proc.wait() != 0:
        raise SystemExit(f"vtk_raycast.py: {' '.join(cmd)} failed ({proc.returncode})")
    with open(stats_path) as f:
        st = json.load(f)
    steady = lines[-args.frames:]
    frame_ms = [float(l.split(" ms render, ")[1].split(" ms frame")[0]) for l, _ in steady]
    render_ms = [float(l.split(", ")[-2].split(" ms render")[0]) for l, _ in steady]
    cpu_ms = None
    if len(lines) > args.frames and steady[-1][1] is not None and lines[-args.frames - 1][1]:
        cpu_ms = (steady[-1][1] - lines[-args.frames - 1][1]) * 1e3 / args.frames
    return {
        "command": "OMP_NUM_THREADS=%d %s" % (args.threads, " ".join(rel(c) for c in cmd)),
        "render_threads": args.threads,
        "frames_total": st["frames"],
        "converged": st["converged"],
        "steady_frames": len(steady),
        "ms_per_frame_steady": st["ms_per_frame_steady"],
        "ms_frame": stats_ms(frame_ms),
        "ms_render": stats_ms(render_ms),
        "cpu_ms_frame_mean": cpu_ms,
        "samples_per_ray": st["samples_per_ray"],
        "iterations_per_ray": st["iterations_per_ray"],
        "nodes_per_ray": st["nodes_per_ray"],
        "png": rel(png),
        "stats": rel(stats_path),
    }


def read_rgb(png):
    import vtk
    from vtk.util import numpy_support

    reader = vtk.vtkPNGReader()
    reader.SetFileName(png)
    reader.Update()
    img = reader.GetOutput()
    w, h, _ = img.GetDimensions()
    a = numpy_support.vtk_to_numpy(img.GetPointData().GetScalars())
    return a.reshape(h, w, -1)[:, :, :3].astype(np.int32)


def main():
    args = parse_args()
    if not args.no_xvfb and not os.environ.get("DISPLAY") and shutil.which("xvfb-run"):
        env = dict(os.environ, LP_NUM_THREADS=str(args.threads))
        cmd = ["xvfb-run", "-a", "-s", "-screen 0 1280x1024x24", sys.executable,
               os.path.abspath(__file__), "--no-xvfb"] + sys.argv[1:]
        os.execvpe("xvfb-run", cmd, env)

    with open(args.scene) as f:
        scene = json.load(f)
    os.makedirs(args.work, exist_ok=True)
    n = args.size
    spec = f"procedural:sphere:{n}x{n}x{n}"
    load_before = load_avg()

    vol = sphere_volume(n)
    if args.type == "u8":
        # The u8 sphere: round(255 v), written raw and converted to a brick store, which
        # resoct opens like a user's file (level-0 leaves scanned as bricks load).
        vol = np.rint(vol.astype(np.float64) * 255.0).astype(np.uint8)
        raw_path = os.path.join(args.work, f"sphere_{n}_u8.raw")
        with open(raw_path, "wb") as f:
            f.write(vol.tobytes(order="C"))
        spec = os.path.join(args.work, f"sphere_{n}_u8.rbs")
        subprocess.run([args.resoct_convert, raw_path, spec, "--dims", f"{n}x{n}x{n}", "--type",
                        "u8"], check=True, stdout=subprocess.DEVNULL)
    raw = vol.tobytes(order="C")
    volume_info = {"spec": rel(spec), "type": args.type,
                   "sha256": hashlib.sha256(raw).hexdigest()}
    if args.verify_raw and args.type == "u8":
        raise SystemExit("vtk_raycast.py: --verify-raw checks the f32 sphere only")
    if args.verify_raw:
        with open(args.verify_raw, "rb") as f:
            ref = f.read()
        same = ref == raw
        volume_info["verified_against"] = rel(args.verify_raw)
        volume_info["bitwise_identical"] = same
        if not same:
            raise SystemExit(f"vtk_raycast.py: the generated sphere differs from {args.verify_raw}")

    vtk_png = os.path.join(args.work, "vtk.png")
    resoct_png = os.path.join(args.work, "resoct.png")
    vtk_result = render_vtk(vol, scene, args, vtk_png)
    resoct_result = render_resoct(args, spec, resoct_png,
                                  os.path.join(args.work, "resoct_stats.json"))
    a, b = read_rgb(vtk_png), read_rgb(resoct_png)
    if a.shape != b.shape:
        raise SystemExit(f"vtk_raycast.py: image sizes differ: {a.shape} vs {b.shape}")
    d = np.abs(a - b)
    diff = {
        "mean_abs_255": float(d.mean()),
        "max_abs_255": int(d.max()),
        "rmse_255": float(np.sqrt((d.astype(np.float64) ** 2).mean())),
        "pixels_over_4_255": float((d.max(axis=2) > 4).mean()),
        "pixels_over_16_255": float((d.max(axis=2) > 16).mean()),
        "note": "8-bit RGB of both PNGs over the scene background; /255 units",
    }
    result = {
        "date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        "machine": {"cpus": os.cpu_count(), "platform": platform.platform(),
                    "load_before": load_before, "load_after": load_avg()},
        "volume": volume_info,
        "scene": os.path.relpath(args.scene, ROOT),
        "image": [scene["viewport"]["width"], scene["viewport"]["height"]],
        "threads": args.threads,
        "vtk": vtk_result,
        "resoct": resoct_result,
        "vtk_over_resoct_ms":
            vtk_result["ms_frame"]["median"] / resoct_result["ms_frame"]["median"],
        "diff": diff,
    }
    out_dir = os.path.dirname(os.path.abspath(args.out))
    os.makedirs(out_dir, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=".peer_vtk.", suffix=".json", dir=out_dir)
    with os.fdopen(fd, "w") as f:
        json.dump(result, f, indent=2)
        f.write("\n")
    os.replace(tmp, args.out)
    print(json.dumps({"vtk_ms_median": vtk_result["ms_frame"]["median"],
                      "resoct_ms_median": resoct_result["ms_frame"]["median"],
                      "mean_abs_255": diff["mean_abs_255"], "max_abs_255": diff["max_abs_255"],
                      "out": rel(args.out)}))


if __name__ == "__main__":
    main()
