"""Checks of bench_renderpark.py's scene conversion and parsing (no rpk
needed): `python3 -m unittest bench/renderpark/test_bench_renderpark.py`.
Not part of `make test`."""

import math
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
