"""Checks of bench_renderpark.py's scene conversion and parsing (no rpk
needed): `python3 -m unittest bench/renderpark/test_bench_renderpark.py`.
Not part of `make test`."""

import math
import re
import os
import struct
import sys
import tempfile
import unittest

sys.path.insert(0, os.path.dirname(__file__))
import bench_renderpark as br  # noqa: E402


def write_ply(path, vertices, faces):
    header = f"ply\nformat binary_little_endian 1.0\nelement vertex {len(vertices)}\nproperty float x\nproperty float y\nproperty float z\nelement face {len(faces)}\nproperty list uchar int vertex_indices\nend_header\n"
    body = b"".join(struct.pack("<3f", *v) for v in vertices) + b"".join(struct.pack("<B3i", 3, *f) for f in faces)
    open(path, "wb").write(header.encode("ascii") + body)


SCENE = """<scene version="3.0.0">
  <shape type="ply" id="m000-wall"><string name="filename" value="scene/wall.ply"/>
    <bsdf type="diffuse"><rgb name="reflectance" value="0.5, 0.25, 0.125"/></bsdf></shape>
  <shape type="ply" id="m001-lamp"><string name="filename" value="scene/lamp.ply"/>
    <bsdf type="diffuse"><rgb name="reflectance" value="0.78 0.78 0.78"/></bsdf>
    <emitter type="area"><rgb name="radiance" value="17, 12, 4"/></emitter></shape>
</scene>"""


class Conversion(unittest.TestCase):
    def convert(self, scene=SCENE):
        d = tempfile.mkdtemp()
        os.makedirs(os.path.join(d, "scene"))
        # 0.1 is not a float32: the file keeps float32(0.1), which MGF must carry exactly.
        write_ply(os.path.join(d, "scene", "wall.ply"), [(0, 0, 0), (1, 0, 0), (0, 0.1, 2)], [(0, 1, 2)])
        write_ply(os.path.join(d, "scene", "lamp.ply"), [(0, 1, 0), (0, 1, 1), (1, 1, 0), (1, 1, 1)], [(0, 1, 2), (2, 1, 3)])
        open(os.path.join(d, "scene.xml"), "w").write(scene)
        return br.mgf(os.path.join(d, "scene.xml"))

    def test_luminance_and_chromaticity(self):
        # Rec.709's white, its luminance 1, and a primary's chromaticity.
        x, y, luminance = br.chromaticity([1.0, 1.0, 1.0])
        self.assertAlmostEqual(x, 0.3127, places=4)
        self.assertAlmostEqual(y, 0.3290, places=4)
        self.assertAlmostEqual(luminance, 1.0, places=6)
        x, y, _ = br.chromaticity([1.0, 0.0, 0.0])
        self.assertAlmostEqual(x, 0.64, places=3)
        self.assertAlmostEqual(y, 0.33, places=3)

    def test_reflectance_emission_and_geometry(self):
        text = self.convert()
        lines = text.split("\n")
        rd = [float(l.split()[1]) for l in lines if l.strip().startswith("rd ")]
        self.assertAlmostEqual(rd[0], 0.2126729 * 0.5 + 0.7151522 * 0.25 + 0.0721750 * 0.125, places=9)
        ed = [float(l.split()[1]) for l in lines if l.strip().startswith("ed ")]
        exitance = math.pi * (0.2126729 * 17 + 0.7151522 * 12 + 0.0721750 * 4)
        self.assertEqual(len(ed), 1)
        self.assertAlmostEqual(ed[0] / br.WHITE_EFFICACY, exitance, places=6)
        self.assertEqual(text.count("\tsides 1"), 2)
        points = [l.split()[1:] for l in lines if l.strip().startswith("p ")]
        self.assertEqual(len(points), 7)
        self.assertEqual(float(points[2][1]), struct.unpack("<f", struct.pack("<f", 0.1))[0])
        # Faces keep their corner order (the front side) and index the
        # second shape's vertices after the first's.
        self.assertEqual([l for l in lines if l.startswith("f ")], ["f v1 v2 v3", "f v4 v5 v6", "f v6 v5 v7"])

    def test_refuses_what_rpk_would_solve_differently(self):
        with self.assertRaisesRegex(br.Refused, "diffuse"):
            self.convert(SCENE.replace('bsdf type="diffuse"><rgb name="reflectance" value="0.5', 'bsdf type="conductor"><rgb name="reflectance" value="0.5'))

    def test_link_count_is_the_last_iteration_s(self):
        log = "Iteration: 1\nNr. interactions: 120\n...\nIteration: 30\nNr. interactions: 27289\n"
        self.assertEqual(br.rpk_links(log), 27289)
        with self.assertRaises(RuntimeError):
            br.rpk_links("no statistics")


if __name__ == "__main__":
    unittest.main()


class Accuracy(unittest.TestCase):
    """Reading bench-surfaces' and compare's output, and the plot."""

    def test_file_label_matches_bench_surfaces(self):
        self.assertEqual(br.file_label("rpk 3e-5"), "rpk-3e-5")
        self.assertEqual(br.file_label("hierarchical-solve 6.5e-4"), "hierarchical-solve-6.5e-4")

    def test_worst_surfaces_and_compare_reports(self):
        md = "| surface | reference | rpk 3e-5 | ours 1e-3 |\n|---|---|---|---|\n| floor | 0.3 | -1.51% | +0.32% |\n| worst surface | | 1.51% | 0.35% |\n"
        self.assertEqual(br.worst_surfaces(md), {"rpk 3e-5": 1.51, "ours 1e-3": 0.35})
        ron = 'Report(\n  figures: {\n    "relative_rmse": 0.0163,\n    "object[floor].mean_signed_error": -0.0059,\n    "object[tall_block].mean_signed_error": 0.0073,\n  },\n)'
        rmse, errors = br.compared(ron)
        self.assertAlmostEqual(rmse, 0.0163)
        self.assertEqual(errors, {"floor": -0.0059, "tall_block": 0.0073})
        table = br.image_table([("rpk 3e-5", (rmse, errors))])
        self.assertIn("| tall_block | +0.73% |", table)
        self.assertIn("| worst surface | 0.73% |", table)

    def test_seeds_images_are_averaged_per_surface_they_share(self):
        # Two seeds' reports; a surface one of them lacks is left out.
        mean = br.averaged([(0.0200, {"floor": -0.004, "tall_block": 0.010}), (0.0180, {"floor": 0.002, "tall_block": 0.006, "ceiling": 0.001})])
        self.assertAlmostEqual(mean[0], 0.0190)
        self.assertEqual(set(mean[1]), {"floor", "tall_block"})
        self.assertAlmostEqual(mean[1]["floor"], -0.001)
        self.assertAlmostEqual(mean[1]["tall_block"], 0.008)
        self.assertEqual(br.averaged([(0.0163, {"floor": -0.0059})]), (0.0163, {"floor": -0.0059}))

    def test_equal_error_interpolates_log_log_between_our_neighbours(self):
        # rpk 3e-5 at 1.63% in 0.134 s; ours 1.91% at 0.209 s and 1.34% at
        # 0.350 s (make bench-renderpark at 986a593): 1.63% at
        # 0.209 (0.350 / 0.209)^(ln(1.91/1.63) / ln(1.91/1.34)) s.
        results = [("rpk 3e-5", (0.0163, {})), ("rpk 1e-5", (0.0100, {})),
                   ("hierarchical-solve 1e-3", (0.0191, {})), ("hierarchical-solve 6.5e-4", (0.0134, {}))]
        medians = {"rpk 3e-5": 0.134, "rpk 1e-5": 0.257, "hierarchical-solve 1e-3": 0.209, "hierarchical-solve 6.5e-4": 0.350}
        table = br.equal_error(results, medians)
        t = 0.209 * (0.350 / 0.209) ** (math.log(1.91 / 1.63) / math.log(1.91 / 1.34))
        self.assertIn(f"| rpk 3e-5 | 1.63% | 0.134 s | {t:.3f} s | {t / 0.134:.2f} |", table)
        self.assertAlmostEqual(t / 0.134, 1.96, places=2)
        self.assertIn("| rpk 1e-5 | 1.00% | 0.257 s | not reached | - |", table)

    def test_axis_ends_are_one_two_five(self):
        self.assertEqual([br.nice(v, True) for v in (0.071, 0.1, 0.37, 4.67)], [0.05, 0.1, 0.2, 2.0])
        self.assertEqual([br.nice(v, False) for v in (0.071, 0.1, 0.37, 4.67)], [0.1, 0.1, 0.5, 5.0])

    def test_plot_places_points_on_log_scales(self):
        svg = br.plot_svg("t", [("a", "red", False, [(0.1, 1.0), (1.0, 10.0)]), ("b", "blue", True, [(0.3, 3.0)])])
        self.assertTrue(svg.startswith("<svg") and svg.rstrip().endswith("</svg>"))
        self.assertEqual(svg.count("<polyline"), 2)
        self.assertEqual(svg.count("<circle"), 3)
        self.assertIn('stroke-dasharray="6 4"', svg)
        # Axes 0.1-1 s and 1-10 %: the first point at the plot's lower
        # left corner, the second at its upper right.
        first = re.search(r'<circle cx="([0-9.]+)" cy="([0-9.]+)"', svg)
        self.assertEqual((float(first.group(1)), float(first.group(2))), (70.0, 390.0))
