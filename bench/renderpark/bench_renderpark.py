"""`make bench-renderpark`: hierarchical-solve against RenderPark's solve.

Issue 10 set the solve a peer: RenderPark's hierarchical Galerkin
radiosity with clustering (the rpkCpp port of RenderPark, one thread,
Jacobi, 30 iterations), which on the built-in Cornell box puts every
surface within 0.7% of a converged path-traced reference at its
link-error threshold 3e-5 (27k links) and within 4% at 1e-4 (11.8k
links). Its times in the issue came from another machine and day; this
measures both programs on this machine, in one run:

1. scene: the pipeline's Mitsuba export (export-mitsuba: PLY meshes,
   diffuse reflectances and area emitters, linear Rec.709 RGB) converted
   to MGF ([`mgf`]): the triangles exactly, each material one-sided, its
   colour as the CIE chromaticity of the RGB value and its `rd` as the
   value's luminance Y; an emitter's `ed` is 183.07 lm/W (rpkCpp's
   WHITE_EFFICACY, which it divides `ed` by) times the luminance of its
   exitance pi L. rpk then runs with Rec.709 primaries and a D65 white
   (`-red ... -white ...`), so the RGB it solves in is the export's.
   The link counts it prints check the configuration: 27,289 at 3e-5 and
   11,820 at 1e-4 on the built-in Cornell box, the issue's 27k and 11.8k
   (rpk's default primaries give 25,447 and 11,069).
2. runs, interleaved so that a change of the machine's speed shows in
   every series alike: per round, rpk at each threshold, then
   hierarchical-solve at each EPS on one thread (RAYON_NUM_THREADS=1); the
   first round is a warm-up and not counted. A time is a whole process's
   wall clock (reading the scene, solving, and for hierarchical-solve
   writing its solution); rpk writes no image (`-raytracing-method none`,
   no save file) and its per-iteration debug print goes to a file.
3. table: per series the median, fastest and slowest time and the link
   count, and hierarchical-solve's median over rpk's median at each
   threshold.
4. surfaces: each program's solution, measured alike (`bench-surfaces`,
   bench/src/surfaces.rs): each surface's mean radiosity over its area
   open to the scene against a hierarchical-solve reference at a much
   finer EPS (`--surfaces` names it); then each input triangle's, where a
   surface's mean may hide errors of opposite sign on its faces
   (triangles.md; its last line printed). rpk runs once more per threshold,
   untimed, saving its model (`-radiance-model-savefile`: every leaf
   element's corners with the radiance of its linear basis there, which
   the Makefile's build of rpk leaves unmapped); hierarchical-solve's are
   its last timed solutions. It is the solve's accuracy.
5. images, where a path-traced reference image is given (`make
   bench-peer`'s Mitsuba image): every solution rendered by grid-gather's
   preview and compared with it as bench-peer compares (relative RMSE and
   each surface's mean; emitters and 2 px round edges left out; a
   false-colour map of the relative difference beside each,
   preview-LABEL.diff.png). rpk's
   models become solutions on the mesh (`bench-surfaces --solutions`:
   each leaf two quadtree levels below its element, with the element's
   linear radiance there), so both programs' solutions go through the
   same display: the issue's own measure of rpk (every surface within
   0.7%), taken here in the same run. With `--image-seeds`,
   hierarchical-solve's image errors are the means over the timed seed
   and those ([`averaged`]; each more seed solved once, untimed): rpk is
   deterministic, and one seed's image moves by a few percent of its
   error, more than many a change does.

Standard library only.
"""

import argparse
import math
import os
import re
import shlex
import statistics
import struct
import subprocess
import sys
import time
import xml.etree.ElementTree as ET

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from pareto import time_to_error  # noqa: E402  (bench/pareto.py, shared with bench-peer)

# rpkCpp's luminous efficacy of its "white" (lm/W): it reads an MGF `ed`
# (lm/m^2) as ed / WHITE_EFFICACY W/m^2.
WHITE_EFFICACY = 183.07

# Linear Rec.709 RGB (D65) to CIE XYZ (IEC 61966-2-1).
RGB_TO_XYZ = (
    (0.4124564, 0.3575761, 0.1804375),
    (0.2126729, 0.7151522, 0.0721750),
    (0.0193339, 0.1191920, 0.9503041),
)

# rpk's primaries and white for the RGB above (its -red/-green/-blue/-white).
REC709 = ["-red", "0.64", "0.33", "-green", "0.30", "0.60", "-blue", "0.15", "0.06", "-white", "0.3127", "0.3290"]


class Refused(Exception):
    """Input this converter cannot carry over to MGF (the message says which and why)."""


def chromaticity(rgb):
    """(x, y, Y) of a linear Rec.709 RGB value; the white point's (x, y) for black."""
    x_, y_, z_ = (sum(m * c for m, c in zip(row, rgb)) for row in RGB_TO_XYZ)
    s = x_ + y_ + z_
    if s <= 0.0:
        return 0.3127, 0.3290, 0.0
    return x_ / s, y_ / s, y_


def read_ply(path):
    """Vertices and faces of a binary little-endian PLY with float x, y, z
    and uchar/int face lists, as export-mitsuba writes them."""
    data = open(path, "rb").read()
    end = data.find(b"end_header\n")
    if not data.startswith(b"ply\n") or end < 0:
        raise Refused(f"{path}: not a PLY file")
    header = data[:end].decode("ascii").split("\n")
    if "format binary_little_endian 1.0" not in header:
        raise Refused(f"{path}: only binary little-endian PLY is read")
    counts, props, element = {}, {"vertex": [], "face": []}, None
    for line in header:
        w = line.split()
        if w[:1] == ["element"]:
            element = w[1]
            if element not in props:
                raise Refused(f"{path}: element '{element}' is not read")
            counts[element] = int(w[2])
        elif w[:1] == ["property"]:
            props[element].append(w[1:])
    if props["vertex"] != [["float", "x"], ["float", "y"], ["float", "z"]] or [p[:3] for p in props["face"]] != [["list", "uchar", "int"]]:
        raise Refused(f"{path}: properties {props} are not float x, y, z and a uchar/int face list")
    at = end + len(b"end_header\n")
    vertices = [struct.unpack_from("<3f", data, at + 12 * i) for i in range(counts["vertex"])]
    at += 12 * counts["vertex"]
    faces = []
    for _ in range(counts["face"]):
        n = data[at]
        faces.append(struct.unpack_from(f"<{n}i", data, at + 1))
        at += 1 + 4 * n
    if at != len(data):
        raise Refused(f"{path}: {len(data) - at} bytes after the last face")
    return vertices, faces


def rgb_value(element, name, where):
    node = element.find(f"rgb[@name='{name}']")
    if node is None:
        raise Refused(f"{where}: no rgb '{name}'")
    return [float(v) for v in node.get("value").replace(",", " ").split()]


def mgf(xml_path):
    """The MGF text of an export-mitsuba scene (see the module's doc)."""
    root = ET.parse(xml_path).getroot()
    base = os.path.dirname(os.path.abspath(xml_path))
    lines = [f"# {os.path.basename(xml_path)} as MGF for RenderPark (bench/renderpark/bench_renderpark.py)"]
    n_vertices = 0
    for shape in root.findall("shape"):
        name = re.sub(r"[^A-Za-z0-9_]", "_", shape.get("id", f"shape{len(lines)}"))
        where = f"{xml_path}: shape {name}"
        bsdf = shape.find("bsdf")
        if shape.get("type") != "ply" or bsdf is None or bsdf.get("type") != "diffuse":
            raise Refused(f"{where}: only PLY shapes with a diffuse BSDF convert (RenderPark's Galerkin solve is diffuse)")
        lines += [f"o {name}", f"m {name} =", "\tsides 1"]
        x, y, luminance = chromaticity(rgb_value(bsdf, "reflectance", where))
        lines += ["\tc", f"\t\tcxy {x:.9f} {y:.9f}", f"\trd {luminance:.9f}"]
        emitter = shape.find("emitter")
        if emitter is not None:
            if emitter.get("type") != "area":
                raise Refused(f"{where}: emitter '{emitter.get('type')}' is not an area emitter")
            x, y, luminance = chromaticity([math.pi * c for c in rgb_value(emitter, "radiance", where)])
            lines += ["\tc", f"\t\tcxy {x:.9f} {y:.9f}", f"\ted {WHITE_EFFICACY * luminance:.9f}"]
        vertices, faces = read_ply(os.path.join(base, shape.find("string[@name='filename']").get("value")))
        for v in vertices:
            n_vertices += 1
            lines += [f"v v{n_vertices} =", "\tp {!r} {!r} {!r}".format(*v)]
        first = n_vertices - len(vertices) + 1
        lines += ["f " + " ".join(f"v{first + i}" for i in face) for face in faces]
        lines.append("o")
    return "\n".join(lines) + "\n"


def rpk_links(log):
    """The link count rpk prints after its last iteration ("Nr. interactions")."""
    found = re.findall(r"Nr\. interactions: (\d+)", log)
    if not found:
        raise RuntimeError("rpk printed no 'Nr. interactions'")
    return int(found[-1])


def report_links(path):
    """The links a hierarchical-solve report counts."""
    found = re.search(r'"links":\s*([0-9.]+)', open(path).read())
    if not found:
        raise RuntimeError(f"{path}: no 'links' figure")
    return int(float(found.group(1)))


def timed(command, log_path, env=None):
    """Wall-clock seconds of one process, its output to `log_path`; stops the run if it fails."""
    with open(log_path, "w") as log:
        started = time.perf_counter()
        status = subprocess.run(command, stdout=log, stderr=subprocess.STDOUT, env=env).returncode
        seconds = time.perf_counter() - started
    if status != 0:
        sys.exit(f"bench-renderpark: {command[0]} exited {status} (its output: {log_path})")
    return seconds


def rpk_command(rpk, scene, threshold):
    """rpk's command line for the solve at `threshold` (see the module's doc)."""
    return [rpk, scene, "-force-onesided", *REC709, "-radiance-method", "Galerkin", "-raytracing-method", "none",
            "-gr-iteration-method", "Jacobi", "-gr-hierarchical", "-gr-clustering", "-iterations", "30",
            "-gr-link-error-threshold", threshold]


def file_label(label):
    """The file name bench-surfaces gives a series' solution: its label
    with characters other than letters, digits, '.' and '-' as '-'."""
    return "".join(c if (c.isascii() and c.isalnum()) or c in ".-" else "-" for c in label)


def compared(text):
    """(relative RMSE, {surface: mean signed error}) of a compare report
    (RON text; run with --exclude-emitters, it has no emitter's surface);
    the errors are fractions."""
    found = re.search(r'\n\s*"relative_rmse":\s*([0-9.eE+-]+)', text)
    if not found:
        raise RuntimeError("the compare report has no relative_rmse")
    signed = re.findall(r'"object\[([^\]]+)\]\.mean_signed_error":\s*([0-9.eE+-]+)', text)
    return float(found.group(1)), {k: float(v) for k, v in signed}


def averaged(per_seed):
    """The mean over seeds of `compared`'s (relative RMSE, {surface: mean
    signed error}): what a solution's image errs by on average, where one
    seed's image moves by more than a change measures."""
    n = len(per_seed)
    names = set.intersection(*(set(errors) for _, errors in per_seed))
    return sum(r for r, _ in per_seed) / n, {k: sum(errors[k] for _, errors in per_seed) / n for k in names}


def image_table(results):
    """Markdown: per surface each series' mean signed error in the image,
    then its relative RMSE and its worst surface."""
    names = sorted({k for _, (_, errors) in results for k in errors})
    rows = ["| surface | " + " | ".join(label for label, _ in results) + " |", "|---|" + "---|" * len(results)]
    for n in names:
        rows.append(f"| {n} | " + " | ".join(f"{100 * e[n]:+.2f}%" if n in e else "-" for _, (_, e) in results) + " |")
    rows.append("| relative RMSE | " + " | ".join(f"{100 * r:.2f}%" for _, (r, _) in results) + " |")
    rows.append("| worst surface | " + " | ".join(f"{100 * max(map(abs, e.values())):.2f}%" for _, (_, e) in results) + " |")
    return "\n".join(rows)


def equal_error(results, medians):
    """Markdown: per rpk series, the time hierarchical-solve needs for rpk's
    image relative RMSE (log-log between its Pareto neighbours,
    `bench/pareto.py`) and its ratio to rpk's time; `results` as
    `image_table` takes them, `medians` each label's median time."""
    ours = [(medians[label], r) for label, (r, _) in results if label.startswith("hierarchical-solve ")]
    rows = ["| rpk series | its image relative RMSE | its time | hierarchical-solve's time to it | ratio |", "|---|---|---|---|---|"]
    for label, (r, _) in results:
        if label.startswith("rpk "):
            t = time_to_error(ours, r)
            reached = f"{t:.3f} s | {t / medians[label]:.2f}" if t is not None else "not reached | -"
            rows.append(f"| {label} | {100 * r:.2f}% | {medians[label]:.3f} s | {reached} |")
    return "\n".join(rows)


def worst_surfaces(markdown):
    """{label: worst surface error, %} from bench-surfaces' table."""
    lines = markdown.strip().splitlines()
    labels = [c.strip() for c in lines[0].strip("|").split("|")][2:]
    worst = [c.strip().rstrip("%") for c in lines[-1].strip("|").split("|")][2:]
    return {label: float(w) for label, w in zip(labels, worst)}


def nice(v, below):
    """The nearest 1, 2 or 5 times a power of ten at or below `v` (or at
    or above it): an axis end."""
    steps = [m * 10.0 ** k for k in range(math.floor(math.log10(v)) - 1, math.floor(math.log10(v)) + 2) for m in (1, 2, 5)]
    return max(t for t in steps if t <= v * (1 + 1e-9)) if below else min(t for t in steps if t >= v * (1 - 1e-9))


def plot_svg(title, curves):
    """An SVG plot of error (%) against time (s), both on log scales:
    `curves` a list of (label, colour, dashed, [(seconds, error), ...])."""
    width, height, left, right, top, bottom = 820, 440, 70, 320, 40, 50
    points = [p for _, _, _, ps in curves for p in ps]
    (x0, x1), (y0, y1) = [(nice(min(v), below=True), nice(max(v), below=False)) for v in zip(*points)]
    px = lambda x: left + (width - left - right) * math.log(x / x0) / math.log(x1 / x0)
    py = lambda y: height - bottom - (height - top - bottom) * math.log(y / y0) / math.log(y1 / y0)
    out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" font-family="sans-serif" font-size="12">',
           f'<rect width="{width}" height="{height}" fill="white"/>',
           f'<text x="{left}" y="22" font-size="14">{title}</text>']
    for lo, hi, at, axis in [(x0, x1, px, "x"), (y0, y1, py, "y")]:
        v = 10 ** math.floor(math.log10(lo))
        while v <= hi * 1.0001:
            for m in (1, 2, 5):
                t = v * m
                if lo * 0.9999 <= t <= hi * 1.0001:
                    c = at(t)
                    line = (c, top, c, height - bottom) if axis == "x" else (left, c, width - right, c)
                    out.append('<line x1="%.1f" y1="%.1f" x2="%.1f" y2="%.1f" stroke="#ddd"/>' % line)
                    label = f"{t:g}"
                    out.append(f'<text x="{c:.1f}" y="{height - bottom + 16}" text-anchor="middle">{label}</text>' if axis == "x"
                               else f'<text x="{left - 6}" y="{c + 4:.1f}" text-anchor="end">{label}</text>')
            v *= 10
    out += [f'<rect x="{left}" y="{top}" width="{width - left - right}" height="{height - top - bottom}" fill="none" stroke="black"/>',
            f'<text x="{(left + width - right) / 2}" y="{height - 12}" text-anchor="middle">time, s (one thread)</text>',
            f'<text transform="translate(16 {(top + height - bottom) / 2}) rotate(-90)" text-anchor="middle">error, %</text>']
    for k, (label, colour, dashed, ps) in enumerate(curves):
        ps = sorted(ps)
        dash = ' stroke-dasharray="6 4"' if dashed else ""
        path = " ".join(f"{px(x):.1f},{py(y):.1f}" for x, y in ps)
        out.append(f'<polyline points="{path}" fill="none" stroke="{colour}" stroke-width="2"{dash}/>')
        out += [f'<circle cx="{px(x):.1f}" cy="{py(y):.1f}" r="3.5" fill="{colour}"/>' for x, y in ps]
        ly = top + 16 + 20 * k
        out.append(f'<line x1="{width - right + 12}" y1="{ly - 4}" x2="{width - right + 40}" y2="{ly - 4}" stroke="{colour}" stroke-width="2"{dash}/>')
        out.append(f'<text x="{width - right + 46}" y="{ly}">{label}</text>')
    return "\n".join(out + ["</svg>"]) + "\n"


def table(series, thresholds):
    """Markdown rows: per series its median (fastest-slowest) time and
    links, and for hierarchical-solve its median over each rpk threshold's."""
    rpk = {t: statistics.median(series[("rpk", t)]["times"]) for t in thresholds}
    head = "| program | setting | links | time, median (fastest-slowest) | runs | " + " | ".join(f"over rpk {t}" for t in thresholds) + " |"
    rows = [head, "|" + "---|" * (5 + len(thresholds))]
    for (program, setting), s in series.items():
        median = statistics.median(s["times"])
        ratios = " | ".join(f"{median / rpk[t]:.2f}" if program != "rpk" else "" for t in thresholds)
        rows.append(f"| {program} | {setting} | {s['links']} | {median:.3f} s ({min(s['times']):.3f}-{max(s['times']):.3f}) | {len(s['times'])} | {ratios} |")
    return "\n".join(rows)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--xml", required=True, help="the scene as export-mitsuba wrote it")
    ap.add_argument("--rpk", required=True, help="the rpk executable (rpkCpp)")
    ap.add_argument("--thresholds", default="3e-5,1e-4", help="rpk's -gr-link-error-threshold values")
    ap.add_argument("--solve", required=True, help="hierarchical-solve's command line without --eps, --seed, -o, --report")
    ap.add_argument("--eps", default="6e-4", help="hierarchical-solve's EPS values")
    ap.add_argument("--seed", default="1")
    ap.add_argument("--image-seeds", default="", help="more seeds, comma-separated, whose solutions' images are averaged with the timed seed's (solved untimed)")
    ap.add_argument("--runs", type=int, default=9, help="counted rounds (one warm-up round more)")
    ap.add_argument("--surfaces", required=True, help="bench-surfaces' command line without -o and the series (its mesh, manifest and reference)")
    ap.add_argument("--image-reference", help="a path-traced image of the scene (bench-peer's); renders and compares every solution")
    ap.add_argument("--preview", help="grid-gather's command line for the preview, without --solution, -o and --report")
    ap.add_argument("--compare", help="compare's command line without the two images and -o")
    ap.add_argument("--out", required=True)
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    try:
        text = mgf(a.xml)
    except (Refused, OSError, ET.ParseError) as e:
        sys.exit(f"bench-renderpark: {e}")
    scene = os.path.join(a.out, "scene.mgf")
    open(scene, "w").write(text)
    thresholds, epses = a.thresholds.split(","), a.eps.split(",")
    series = {("rpk", t): {"times": [], "links": None} for t in thresholds}
    series.update({("hierarchical-solve", e): {"times": [], "links": None} for e in epses})
    one_thread = dict(os.environ, RAYON_NUM_THREADS="1")
    for round_ in range(a.runs + 1):
        for t in thresholds:
            log = os.path.join(a.out, f"rpk-{t}.log")
            seconds = timed(rpk_command(a.rpk, scene, t), log)
            s = series[("rpk", t)]
            s["links"] = rpk_links(open(log, errors="replace").read())
            if round_ > 0:
                s["times"].append(seconds)
        for e in epses:
            solution = os.path.join(a.out, f"solution-{e}.exr")
            seconds = timed(shlex.split(a.solve) + ["--eps", e, "--seed", a.seed, "-o", solution, "--report", solution + ".report.ron"],
                            os.path.join(a.out, f"solve-{e}.log"), one_thread)
            s = series[("hierarchical-solve", e)]
            s["links"] = report_links(solution + ".report.ron")
            if round_ > 0:
                s["times"].append(seconds)
        print(f"bench-renderpark: round {round_}/{a.runs}{' (warm-up)' if round_ == 0 else ''}", file=sys.stderr)
    result = table(series, thresholds)
    open(os.path.join(a.out, "table.md"), "w").write(result + "\n")
    print(result)
    models = []
    for t in thresholds:
        model = os.path.join(a.out, f"rpk-{t}.wrl")
        timed(rpk_command(a.rpk, scene, t) + ["-radiance-model-savefile", model], os.path.join(a.out, f"rpk-{t}-model.log"))
        models.append(f"rpk {t}={model}")
    solutions = [f"hierarchical-solve {e}={os.path.join(a.out, f'solution-{e}.exr')}" for e in epses]
    surfaces = os.path.join(a.out, "surfaces.md")
    converted = os.path.join(a.out, "rpk-solutions")
    status = subprocess.run(shlex.split(a.surfaces) + ["-o", surfaces, "--solutions", converted, *models, *solutions]).returncode
    triangles = os.path.join(a.out, "triangles.md")
    status = status or subprocess.run(shlex.split(a.surfaces) + ["--by", "triangle", "-o", triangles, *models, *solutions], stdout=subprocess.DEVNULL).returncode
    if status != 0:
        sys.exit(f"bench-renderpark: bench-surfaces exited {status}")
    print(f"per input triangle ({triangles}): {open(triangles).read().strip().splitlines()[-1]}")
    if not a.image_reference:
        print("bench-renderpark: no reference image (make bench-peer makes one): the images are not compared", file=sys.stderr)
        return
    rendered = [(m.split("=", 1)[0], os.path.join(converted, file_label(m.split("=", 1)[0]) + ".exr")) for m in models]
    rendered += [tuple(x.split("=", 1)) for x in solutions]
    def image_error(label, solution):
        image, report = os.path.join(a.out, f"preview-{file_label(label)}.exr"), os.path.join(a.out, f"compare-{file_label(label)}.ron")
        timed(shlex.split(a.preview) + ["--solution", solution, "-o", image, "--report", image + ".report.ron"], image + ".log")
        timed(shlex.split(a.compare) + [image, a.image_reference, "-o", report, "--diff", image.replace(".exr", ".diff.png")], report + ".log")
        return compared(open(report).read())

    seeds = [s for s in a.image_seeds.split(",") if s]
    results = []
    for label, solution in rendered:
        per_seed = [image_error(label, solution)]
        if label.startswith("hierarchical-solve "):
            e = label.split(" ", 1)[1]
            for seed in seeds:
                more = os.path.join(a.out, f"solution-{e}-seed-{seed}.exr")
                timed(shlex.split(a.solve) + ["--eps", e, "--seed", seed, "-o", more, "--report", more + ".report.ron"], os.path.join(a.out, f"solve-{e}-seed-{seed}.log"))
                per_seed.append(image_error(f"{label} seed {seed}", more))
        results.append((label, averaged(per_seed)))
    if seeds:
        print(f"bench-renderpark: hierarchical-solve's images are the means over seeds {a.seed},{a.image_seeds}", file=sys.stderr)
    medians = {f"{program} {setting}": statistics.median(v["times"]) for (program, setting), v in series.items()}
    images = image_table(results) + "\n\nAt equal image error (medians of the timed rounds):\n\n" + equal_error(results, medians)
    open(os.path.join(a.out, "images.md"), "w").write(images + "\n")
    print(images)
    worst = worst_surfaces(open(surfaces).read())
    curves = []
    for program, colour in [("rpk", "#d95f02"), ("hierarchical-solve", "#1b6ac9")]:
        mine = [(label, r) for label, r in results if label.startswith(program + " ")]
        curves.append((f"{program}: image, relative RMSE", colour, False, [(medians[label], 100 * r[0]) for label, r in mine]))
        curves.append((f"{program}: solution, worst surface", colour, True, [(medians[label], worst[label]) for label, _ in mine]))
    plot = os.path.join(a.out, "renderpark.svg")
    open(plot, "w").write(plot_svg("Cornell box: error against time, RenderPark and hierarchical-solve", curves))
    print(f"bench-renderpark: {plot}", file=sys.stderr)


if __name__ == "__main__":
    main()
