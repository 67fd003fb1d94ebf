"""`make bench-peer`: this pipeline against Mitsuba 3 on the same scene.

Time to a given error for both renderers, measured in one run on one
machine, against one converged Mitsuba reference:

1. variant: `llvm_ad_rgb` where its JIT works (libLLVM >= 16 found, probed
   in a child process since a broken LLVM aborts the process), else
   `scalar_rgb`; printed.
2. reference: two independent halves (disjoint seeds), each rendered in
   chunks until the reference's own noise is below a fifth of the smallest
   target or the time budget is spent. Noise estimate: the halves differ by
   noise only, so E|h1 - h2|^2 = 2 s^2 per pixel and channel (s^2: one
   half's variance) while the reference (h1 + h2) / 2 has variance s^2 / 2;
   hence relRMSE(reference) = relRMSE(h1, h2) / 2.
3. in one run, interleaved: Mitsuba at increasing spp (repetition 1), the
   pipeline's sweep against the reference (`sweep --reference`), Mitsuba
   repetitions 2.. (so a change in machine load shows in Mitsuba's spread).
   A Mitsuba point's time is scene load + render + evaluation in a warm
   process, the median of its repetitions (JIT kernels are cached after the
   first); its error is the RMS over repetitions (each its own seed).
4. errors: `compare`'s relative RMSE, sqrt(sum (a - b)^2 / sum b^2) over
   pixels and channels, over the diffuse surfaces: emitters and pixels
   within 2 px of an edge or an emitter left out. The pipeline's points are
   measured by `compare` itself (inside `sweep`); Mitsuba images carry no
   surface channels, so their errors are computed here with the mask
   `compare` uses, taken from a pipeline image's `surface` channels; the
   two computations are checked against each other on that pipeline image
   (the run stops if they differ).
5. time to error for 5%, 2%, 1%: over each series' Pareto front (points
   sorted by time, each better than every faster one), the time where the
   error first reaches the target, interpolated log-log between the
   neighbouring points; "not reached" where it never does; ratio = Mitsuba
   time / pipeline time. Written as a table (text and CSV) and an SVG plot.
6. per surface: the mean signed error (luminance) of every object for
   Mitsuba's largest spp and for each pipeline series' most accurate point
   (from the `compare` reports the sweep keeps, [`best_runs`]).

Standard library, numpy and mitsuba only.
"""

import argparse
import csv
import glob
import hashlib
import json
import math
import os
import re
import shlex
import subprocess
import sys
import time

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from pareto import pareto, time_to_error  # noqa: E402  (bench/pareto.py, shared with bench-renderpark)

LUMINANCE = np.array([0.2126, 0.7152, 0.0722])  # radiometry::color::luminance (BT.709)
NO_SURFACE = 4294967295.0
SINGLE_SURFACE, EMITTER = 1, 2


def log(message):
    print(f"bench-peer: {message}", file=sys.stderr, flush=True)


def atomic_write(path, data):
    tmp = f"{path}.{os.getpid()}.tmp"
    with open(tmp, "wb" if isinstance(data, bytes) else "w") as f:
        f.write(data)
    os.replace(tmp, path)


# --- variant ---------------------------------------------------------------

LLVM_CANDIDATES = [
    "/usr/lib/x86_64-linux-gnu/libLLVM.so.19*",
    "/usr/lib/x86_64-linux-gnu/libLLVM-19.so*",
    "/usr/lib/llvm-19/lib/libLLVM*.so*",
    "/usr/lib/x86_64-linux-gnu/libLLVM.so.2[0-9]*",
    "/usr/lib/llvm-2[0-9]/lib/libLLVM*.so*",
]

PROBE = "import mitsuba as mi; mi.set_variant('llvm_ad_rgb'); import drjit as dr; dr.eval(mi.render(mi.load_dict(mi.cornell_box()), spp=1))"


def choose_variant(requested):
    if requested != "auto":
        return requested
    env = dict(os.environ)
    if "DRJIT_LIBLLVM_PATH" not in env:
        found = sorted(p for pattern in LLVM_CANDIDATES for p in glob.glob(pattern))
        if found:
            env["DRJIT_LIBLLVM_PATH"] = found[0]
    probe = subprocess.run([sys.executable, "-c", PROBE], env=env, capture_output=True, text=True, timeout=300)
    if probe.returncode == 0:
        os.environ.update({k: v for k, v in env.items() if k == "DRJIT_LIBLLVM_PATH"})
        log(f"Mitsuba variant: llvm_ad_rgb (DRJIT_LIBLLVM_PATH={env.get('DRJIT_LIBLLVM_PATH', 'system default')})")
        return "llvm_ad_rgb"
    why = (probe.stderr.strip().splitlines() or [f"exit {probe.returncode}"])[-1][:160]
    log(f"Mitsuba variant: scalar_rgb (llvm_ad_rgb failed: {why}; `apt-get install libllvm19` gives it a working LLVM)")
    return "scalar_rgb"


# --- images and the compared pixels -----------------------------------------

def read_exr(mi, path):
    """(rgb [h, w, 3] float64, channels dict name -> [h, w]) of any EXR."""
    bitmap = mi.Bitmap(path)
    s = bitmap.struct_()
    names = [s[i].name for i in range(len(s))]
    pixels = np.array(bitmap, copy=True).astype(np.float64)
    if pixels.ndim == 2:
        pixels = pixels[..., None]
    channels = {n: pixels[..., i] for i, n in enumerate(names)}
    rgb = np.stack([channels[c] for c in "RGB"], axis=-1)
    return rgb, channels


def dilate(mask, n):
    """`mask` grown by n pixels in the Chebyshev metric (compare's dilate)."""
    if n == 0:
        return mask.copy()
    h, w = mask.shape
    padded = np.pad(mask, n)
    out = np.zeros_like(mask)
    for dy in range(2 * n + 1):
        for dx in range(2 * n + 1):
            out |= padded[dy:dy + h, dx:dx + w]
    return out


def compared_pixels(channels, edges):
    """compare's mask for `--exclude-emitters --exclude-edges N`, from a
    pipeline image's surface channels."""
    for name in ("surface.object", "surface.flags"):
        if name not in channels:
            raise SystemExit(f"bench-peer: error: the pipeline image has no {name} channel (render it with this grid-gather)")
    flags = channels["surface.flags"].astype(np.int64)
    emitter = (flags & EMITTER) != 0
    keep = (channels["surface.object"] != NO_SURFACE) & ~emitter
    edge = ((flags & SINGLE_SURFACE) == 0) | emitter
    return keep & ~dilate(edge, edges)


def relative_rmse(a, b, mask):
    d = ((a - b)[mask] ** 2).sum()
    r = (b[mask] ** 2).sum()
    return math.sqrt(d / r) if r > 0 else 0.0


def mean_signed_error(a, b, mask):
    la, lb = a[mask] @ LUMINANCE, b[mask] @ LUMINANCE
    return float((la - lb).sum() / lb.sum()) if lb.sum() > 0 else 0.0


def per_object(a, b, mask, objects, names):
    rows = []
    for index in sorted(set(objects[mask].astype(np.int64).tolist())):
        m = mask & (objects == index)
        label = names[index] if index < len(names) else f"#{index}"
        rows.append((label, int(m.sum()), relative_rmse(a, b, m), mean_signed_error(a, b, m)))
    return rows


def against_reference(label, rgb, ref, mask, objects, names):
    """Two lines: `label`'s relative RMSE and mean signed error against the
    reference over the compared pixels, and its mean signed error per
    object (how each solver's image of the scene is reported)."""
    return [f"{label} vs the Mitsuba reference: relative RMSE {100 * relative_rmse(rgb, ref, mask):.2f}%, mean signed error {100 * mean_signed_error(rgb, ref, mask):+.2f}%",
            "  per object: " + "; ".join(f"{n} {100 * m:+.2f}%" for n, _, _, m in per_object(rgb, ref, mask, objects, names))]


def named_image(text):
    """`NAME=IMAGE` of --also: (name, path)."""
    name, sep, path = text.partition("=")
    if not sep or not name or not path:
        raise argparse.ArgumentTypeError(f"--also takes NAME=IMAGE, not {text!r}")
    return name, path


def manifest_objects(path):
    text = open(path).read()
    found = re.search(r"\bobjects:\s*\[(.*?)\]", text, re.S)
    return re.findall(r'"((?:[^"\\]|\\.)*)"', found.group(1)) if found else []


# --- Mitsuba ----------------------------------------------------------------

class Renderer:
    def __init__(self, mi, xml):
        self.mi, self.xml = mi, xml

    def spp(self, spp):
        """The sample count the sampler really takes (multijitter rounds
        `spp` up to a grid of near-square strata)."""
        return int(self.mi.load_file(self.xml, spp=spp).sensors()[0].sampler().sample_count())

    def render(self, spp, seed):
        import drjit as dr
        started = time.perf_counter()
        scene = self.mi.load_file(self.xml, spp=spp)
        image = self.mi.render(scene, spp=spp, seed=seed)
        dr.eval(image)
        dr.sync_thread()  # the LLVM backend runs kernels asynchronously
        pixels = np.array(image, copy=True)
        seconds = time.perf_counter() - started
        return pixels.astype(np.float64)[..., :3], seconds

    def write(self, path, pixels):
        tmp = f"{path}.{os.getpid()}.tmp.exr"
        self.mi.Bitmap(pixels.astype(np.float32), self.mi.Bitmap.PixelFormat.RGB).write(tmp)
        os.replace(tmp, path)


def reference(renderer, args, mask, goal):
    """The converged reference: two halves grown chunk by chunk."""
    out = args.out
    meta_path = os.path.join(out, "reference.json")
    key = {"xml_sha256": hashlib.sha256(open(args.xml, "rb").read()).hexdigest(), "variant": args.variant_used, "chunk_spp": args.ref_chunk_spp}
    sums, chunks, seconds = [None, None], 0, 0.0
    if os.path.exists(meta_path) and not args.fresh_reference:
        meta = json.load(open(meta_path))
        if meta.get("key") == key and os.path.exists(os.path.join(out, "reference_sums.npy")):
            sums = list(np.load(os.path.join(out, "reference_sums.npy")))
            chunks, seconds = meta["chunks"], meta["seconds"]
            log(f"reference: resuming {chunks} chunks per half ({seconds:.0f} s) from {meta_path}")
    noise = float("inf")
    while True:
        if chunks > 0:
            halves = [s / chunks for s in sums]
            noise = relative_rmse(halves[0], halves[1], mask) / 2
            log(f"reference: {chunks * renderer.spp(args.ref_chunk_spp)} spp per half, {seconds:.0f} s, noise {100 * noise:.3f}% (goal {100 * goal:.3f}%)")
        if chunks > 0 and (noise <= goal or seconds >= args.ref_budget_s):
            break
        for half in (0, 1):
            # Seeds 10^6 + 2 chunk + half: disjoint from each other and from the sweep's.
            pixels, t = renderer.render(args.ref_chunk_spp, 1_000_000 + 2 * chunks + half)
            sums[half] = pixels if sums[half] is None else sums[half] + pixels
            seconds += t
        chunks += 1
        np.save(os.path.join(out, "reference_sums.tmp.npy"), np.stack(sums))
        os.replace(os.path.join(out, "reference_sums.tmp.npy"), os.path.join(out, "reference_sums.npy"))
        atomic_write(meta_path, json.dumps({"key": key, "chunks": chunks, "seconds": seconds}))
    halves = [s / chunks for s in sums]
    ref = (halves[0] + halves[1]) / 2
    renderer.write(os.path.join(out, "reference.exr"), ref)
    renderer.write(os.path.join(out, "reference_half1.exr"), halves[0])
    renderer.write(os.path.join(out, "reference_half2.exr"), halves[1])
    return ref, noise, 2 * chunks * renderer.spp(args.ref_chunk_spp), seconds


# --- time to error ------------------------------------------------------------

def read_sweep(path):
    """Series of the pipeline's sweep.csv: {"hierarchical/preview": [(total_s, error, label)]}."""
    series = {}
    with open(path) as f:
        rows = list(csv.DictReader(f))
    fixed = {"solver", "gather", "cluster_s", "solve_s", "gather_s", "total_s", "total_min_s", "total_max_s", "error", "error_min", "error_max", "worst_surface", "worst_surface_min", "worst_surface_max", "pareto", "reference"}
    for row in rows:
        knobs = ", ".join(f"{k}={v}" for k, v in row.items() if k not in fixed and v not in ("", None))
        series.setdefault(f"{row['solver']}/{row['gather']}", []).append((float(row["total_s"]), float(row["error"]), knobs))
    return series


def best_runs(sweep_dir, names):
    """Per series ("solver/gather"), its most accurate run of the sweep:
    (its point's folder, e.g. "EPS=0.0001"; relative RMSE; [(object, mean
    signed error)]), read from
    the `compare-<gather>.ron` reports the sweep keeps under
    runs/<solver>/<point>/rep<k>/ (`compare`'s per-object luminance means)."""
    best = {}
    for path in sorted(glob.glob(os.path.join(sweep_dir, "runs", "*", "*", "rep*", "compare-*.ron"))):
        text = open(path).read()
        found = re.search(r'"relative_rmse":\s*([0-9.eE+-]+)', text)
        if not found:
            continue
        solver = os.path.basename(os.path.dirname(os.path.dirname(os.path.dirname(path))))
        gather = os.path.basename(path)[len("compare-"):-len(".ron")]
        error = float(found.group(1))
        key = f"{solver}/{gather}"
        if key not in best or error < best[key][1]:
            means = [(int(i), float(v)) for i, v in re.findall(r'"object\[#(\d+)\]\.mean_signed_error":\s*([0-9.eE+-]+)', text)]
            objects = [(names[i] if i < len(names) else f"#{i}", v) for i, v in sorted(means)]
            best[key] = (os.path.basename(os.path.dirname(os.path.dirname(path))), error, objects)
    return best


# --- output -------------------------------------------------------------------

def svg_plot(series, targets, title):
    """Error against time, log-log, one polyline per series."""
    width, height, left, right, top, bottom = 720, 460, 70, 200, 40, 50
    points = [(t, e) for s in series.values() for t, e, _ in s if t > 0 and e > 0]
    t_lo, t_hi = min(p[0] for p in points), max(p[0] for p in points)
    e_lo, e_hi = min([p[1] for p in points] + targets), max([p[1] for p in points] + targets)
    lt0, lt1 = math.floor(math.log10(t_lo)), math.ceil(math.log10(t_hi))
    le0, le1 = math.floor(math.log10(e_lo)), math.ceil(math.log10(e_hi))
    if lt1 == lt0:
        lt1 += 1
    if le1 == le0:
        le1 += 1
    x = lambda t: left + (math.log10(t) - lt0) / (lt1 - lt0) * (width - left - right)
    y = lambda e: top + (le1 - math.log10(e)) / (le1 - le0) * (height - top - bottom)
    colours = ["#d62728", "#1f77b4", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b"]
    out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" font-family="sans-serif" font-size="12">',
           f'<rect width="{width}" height="{height}" fill="white"/>',
           f'<text x="{left}" y="22" font-size="14">{title}</text>']
    for k in range(lt0, lt1 + 1):
        out.append(f'<line x1="{x(10**k):.1f}" y1="{top}" x2="{x(10**k):.1f}" y2="{height - bottom}" stroke="#ddd"/>')
        out.append(f'<text x="{x(10**k):.1f}" y="{height - bottom + 16}" text-anchor="middle">{10.0**k:g}</text>')
    for k in range(le0, le1 + 1):
        out.append(f'<line x1="{left}" y1="{y(10**k):.1f}" x2="{width - right}" y2="{y(10**k):.1f}" stroke="#ddd"/>')
        out.append(f'<text x="{left - 6}" y="{y(10**k) + 4:.1f}" text-anchor="end">{100 * 10.0**k:g}%</text>')
    for target in targets:
        out.append(f'<line x1="{left}" y1="{y(target):.1f}" x2="{width - right}" y2="{y(target):.1f}" stroke="#999" stroke-dasharray="4 3"/>')
    out.append(f'<text x="{(left + width - right) / 2}" y="{height - 12}" text-anchor="middle">time, s (log)</text>')
    out.append(f'<text x="16" y="{(top + height - bottom) / 2}" transform="rotate(-90 16 {(top + height - bottom) / 2})" text-anchor="middle">relative RMSE (log)</text>')
    for i, (name, s) in enumerate(series.items()):
        c = colours[i % len(colours)]
        pts = sorted((t, e) for t, e, _ in s if t > 0 and e > 0)
        out.append(f'<polyline fill="none" stroke="{c}" stroke-width="1.5" points="{" ".join(f"{x(t):.1f},{y(e):.1f}" for t, e in pareto(pts))}"/>')
        for t, e in pts:
            out.append(f'<circle cx="{x(t):.1f}" cy="{y(e):.1f}" r="3" fill="{c}"/>')
        out.append(f'<circle cx="{width - right + 16}" cy="{top + 10 + 18 * i}" r="4" fill="{c}"/>')
        out.append(f'<text x="{width - right + 26}" y="{top + 14 + 18 * i}">{name}</text>')
    out.append("</svg>")
    return "\n".join(out) + "\n"


def fmt_time(t):
    return "not reached" if t is None else f"{t:.3g} s"


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--xml", required=True, help="Mitsuba scene from export-mitsuba")
    p.add_argument("--pipeline-image", required=True, help="a pipeline image of the scene at the film size (its surface channels give the compared pixels)")
    p.add_argument("--manifest", required=True, help="manifest.ron (object names)")
    p.add_argument("--compare", default="target/release/compare")
    p.add_argument("--sweep", default="", help="command running the pipeline's sweep; {reference} and {out} are substituted; empty: Mitsuba only")
    p.add_argument("--sweep-csv", default="", help="the table the sweep writes [default: OUT/sweep/sweep.csv]")
    p.add_argument("--out", required=True)
    p.add_argument("--variant", default="auto", choices=["auto", "llvm_ad_rgb", "scalar_rgb"])
    p.add_argument("--spp", default="1,4,16,64,256,1024", help="Mitsuba's points, samples per pixel")
    p.add_argument("--reps", type=int, default=3, help="repetitions per Mitsuba point")
    p.add_argument("--rep-cap-s", type=float, default=20.0, help="a point whose first render takes longer gets no further repetitions")
    p.add_argument("--targets", default="0.05,0.02,0.01")
    p.add_argument("--ref-chunk-spp", type=int, default=256, help="spp of one reference chunk (a square: multijitter rounds others up)")
    p.add_argument("--ref-budget-s", type=float, default=480.0, help="render time the reference may take (both halves)")
    p.add_argument("--fresh-reference", action="store_true", help="render the reference anew even if one with the same scene and variant exists")
    p.add_argument("--exclude-edges", type=int, default=2)
    p.add_argument("--also", type=named_image, action="append", default=[], metavar="NAME=IMAGE",
                   help="another pipeline image of the scene (another solver's preview, the full gather) whose error against the reference is reported beside --pipeline-image's; repeatable")
    args = p.parse_args()
    os.makedirs(args.out, exist_ok=True)
    targets = sorted((float(t) for t in args.targets.split(",")), reverse=True)
    spps = [int(s) for s in args.spp.split(",")]

    args.variant_used = choose_variant(args.variant)
    import mitsuba as mi
    mi.set_variant(args.variant_used)
    renderer = Renderer(mi, args.xml)

    pipeline_rgb, channels = read_exr(mi, args.pipeline_image)
    mask = compared_pixels(channels, args.exclude_edges)
    objects = channels["surface.object"]
    names = manifest_objects(args.manifest)
    log(f"{int(mask.sum())} of {mask.size} pixels compared (emitters and {args.exclude_edges} px around edges and emitters left out)")

    goal = min(targets) / 5
    ref, noise, ref_spp, ref_s = reference(renderer, args, mask, goal)
    ref_path = os.path.join(args.out, "reference.exr")
    if ref.shape != pipeline_rgb.shape:
        raise SystemExit(f"bench-peer: error: {args.pipeline_image} is {pipeline_rgb.shape[1]}x{pipeline_rgb.shape[0]}, the Mitsuba film {ref.shape[1]}x{ref.shape[0]}")
    noisy = [t for t in targets if noise > t / 5]
    if noisy:
        log(f"warning: reference noise {100 * noise:.3f}% is over a fifth of {', '.join(f'{100 * t:g}%' for t in noisy)}: those columns are marked '~' (raise --ref-budget-s)")

    # The pipeline image against the reference: orientation, brightness, and
    # this script's metric tied to compare's.
    lines = []
    ours = relative_rmse(pipeline_rgb, ref, mask)
    flips = {"left-right": ref[:, ::-1], "upside-down": ref[::-1, :]}
    flipped = {k: relative_rmse(pipeline_rgb, v, mask & mask[:, ::-1] if k == "left-right" else mask & mask[::-1, :]) for k, v in flips.items()}
    image_lines = against_reference(f"pipeline image {args.pipeline_image}", pipeline_rgb, ref, mask, objects, names)
    lines.append(image_lines[0])
    lines.append("  orientation: against the reference mirrored " + ", ".join(f"{k} {100 * v:.1f}%" for k, v in flipped.items()) + (" (larger: not mirrored)" if min(flipped.values()) > ours else " (NOT larger: mirrored?)"))
    report = os.path.join(args.out, "pipeline-image.compare.ron")
    cmd = [args.compare, args.pipeline_image, ref_path, "--exclude-emitters", "--exclude-edges", str(args.exclude_edges), "--manifest", args.manifest, "-o", report]
    run = subprocess.run(cmd, capture_output=True, text=True)
    if run.returncode in (0, 1) and os.path.exists(report):
        theirs = float(re.search(r'"relative_rmse":\s*([0-9.eE+-]+)', open(report).read()).group(1))
        lines.append(f"  compare's relative RMSE {100 * theirs:.4f}%, this script's {100 * ours:.4f}%")
        if abs(theirs - ours) > 1e-4 * max(theirs, 1e-12) + 1e-9:
            raise SystemExit("bench-peer: error: this script's masked relative RMSE differs from compare's: the mask or the metric drifted")
    else:
        lines.append(f"  compare could not read the reference ({(run.stderr.strip().splitlines() or ['?'])[-1]}): this script's metric is unchecked")
    lines.append(image_lines[1])
    for name, path in args.also:
        rgb, _ = read_exr(mi, path)
        if rgb.shape != ref.shape:
            raise SystemExit(f"bench-peer: error: {path} is {rgb.shape[1]}x{rgb.shape[0]}, the Mitsuba film {ref.shape[1]}x{ref.shape[0]}")
        lines.extend(against_reference(f"{name} ({path})", rgb, ref, mask, objects, names))
    for line in lines:
        log(line)

    # Interleaved: Mitsuba rep 1, the pipeline sweep, Mitsuba reps 2..n.
    mitsuba_runs = {s: [] for s in spps}
    sweep_series, sweep_s = {}, None
    last = []  # per object, the first repetition at the most samples

    def mitsuba_rep(rep):
        for i, spp in enumerate(spps):
            if rep > 0 and mitsuba_runs[spp] and mitsuba_runs[spp][0][0] > args.rep_cap_s:
                continue
            pixels, t = renderer.render(spp, 1000 * (rep + 1) + i)
            e = relative_rmse(pixels, ref, mask)
            mitsuba_runs[spp].append((t, e))
            if rep == 0 and spp == spps[-1]:
                renderer.write(os.path.join(args.out, f"mitsuba_{spp}spp.exr"), pixels)
                last[:] = per_object(pixels, ref, mask, objects, names)
                log(f"mitsuba {spp} spp per object: " + "; ".join(f"{n} {100 * m:+.2f}%" for n, _, _, m in last))
            log(f"mitsuba rep {rep + 1}: {spp} spp {t:.2f} s, relative RMSE {100 * e:.2f}%")

    mitsuba_rep(0)
    if args.sweep:
        command = args.sweep.format(reference=shlex.quote(ref_path), out=shlex.quote(args.out))
        log(f"pipeline sweep: {command}")
        started, started_wall = time.perf_counter(), time.time()
        subprocess.run(command, shell=True, check=True)
        sweep_s = time.perf_counter() - started
        table = args.sweep_csv or os.path.join(args.out, "sweep", "sweep.csv")
        if not os.path.exists(table) or os.path.getmtime(table) < started_wall:
            raise SystemExit(f"bench-peer: error: the sweep wrote no {table}")
        sweep_series = read_sweep(table)
    for rep in range(1, args.reps):
        mitsuba_rep(rep)

    # Merge.
    series = {}
    mitsuba_name = f"mitsuba {args.variant_used}"
    series[mitsuba_name] = []
    for spp, runs in mitsuba_runs.items():
        times = sorted(t for t, _ in runs)
        median = times[len(times) // 2] if len(times) % 2 else (times[len(times) // 2 - 1] + times[len(times) // 2]) / 2
        rms = math.sqrt(sum(e * e for _, e in runs) / len(runs))
        series[mitsuba_name].append((median, rms, f"spp={renderer.spp(spp)} ({len(runs)} reps)"))
    for name, pts in sweep_series.items():
        series[f"pipeline {name}"] = pts

    header = ["series"] + [f"t@{100 * t:g}%" for t in targets] + [f"ratio@{100 * t:g}%" for t in targets]
    rows = []
    mitsuba_tte = [time_to_error([(t, e) for t, e, _ in series[mitsuba_name]], target) for target in targets]
    for name, pts in series.items():
        tte = [time_to_error([(t, e) for t, e, _ in pts], target) for target in targets]
        ratios = []
        for m, t in zip(mitsuba_tte, tte):
            ratios.append("" if name == mitsuba_name else ("-" if m is None or t is None else f"{m / t:.3g}"))
        rows.append([name] + [("~" if target in noisy and v is not None else "") + fmt_time(v) for target, v in zip(targets, tte)] + ratios)

    text = []
    text.append(f"bench-peer: {args.xml}, Mitsuba {mi.__version__} {args.variant_used}, reference {ref_spp} spp ({ref_s:.0f} s), noise {100 * noise:.3f}% (two halves)")
    text.extend(lines)
    text.append("")
    text.append("points (time s, relative RMSE over the diffuse surfaces):")
    for name, pts in series.items():
        for t, e, label in sorted(pts):
            text.append(f"  {name:<28} {label:<36} {t:9.3f} s {100 * e:8.3f}%")
    text.append("")
    widths = [max(len(r[i]) for r in rows + [header]) for i in range(len(header))]
    text.append("  ".join(h.ljust(w) for h, w in zip(header, widths)))
    for r in rows:
        text.append("  ".join(c.ljust(w) for c, w in zip(r, widths)))
    text.append("ratio: Mitsuba time / pipeline time (> 1: the pipeline is faster); time to error interpolated log-log on each series' Pareto front")
    if noisy:
        text.append("~: the reference's noise is over a fifth of this target: the time is indicative only")
    if sweep_s is not None:
        text.append(f"the pipeline sweep took {sweep_s:.0f} s in all (every point, every rep, compare included)")
        text.append("")
        text.append("per surface, mean signed error (luminance) of each series' most accurate point:")
        text.append(f"  mitsuba {spps[-1]} spp: " + "; ".join(f"{n} {100 * m:+.2f}%" for n, _, _, m in last))
        sweep_dir = os.path.dirname(args.sweep_csv) if args.sweep_csv else os.path.join(args.out, "sweep")
        for name, (run, error, objects) in best_runs(sweep_dir, names).items():
            text.append(f"  {name} {run} ({100 * error:.2f}%): " + "; ".join(f"{n} {100 * m:+.2f}%" for n, m in objects))
    table = "\n".join(text) + "\n"
    print(table, end="")
    atomic_write(os.path.join(args.out, "time_to_error.txt"), table)
    with open(os.path.join(args.out, "points.csv.tmp"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["series", "point", "time_s", "relative_rmse"])
        for name, pts in series.items():
            for t, e, label in sorted(pts):
                w.writerow([name, label, t, e])
    os.replace(os.path.join(args.out, "points.csv.tmp"), os.path.join(args.out, "points.csv"))
    # The scene's name: the folder of make's OUT, which holds mitsuba/scene.xml.
    scene = os.path.basename(os.path.dirname(os.path.dirname(os.path.abspath(args.xml)))) or "scene"
    title = f"{scene}: time to error, Mitsuba 3 ({args.variant_used}) vs this pipeline"
    atomic_write(os.path.join(args.out, "time_to_error.svg"), svg_plot(series, targets, title))


if __name__ == "__main__":
    main()
