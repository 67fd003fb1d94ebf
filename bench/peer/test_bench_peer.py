"""Checks of bench_peer.py's arithmetic (no Mitsuba needed):
`python3 -m unittest bench/peer/test_bench_peer.py` with numpy installed
(the bench's venv has it). Not part of `make test`."""

import os
import sys
import unittest

import numpy as np

sys.path.insert(0, os.path.dirname(__file__))
import bench_peer as bp  # noqa: E402


class TimeToError(unittest.TestCase):
    def test_log_log_between_pareto_neighbours(self):
        points = [(1.0, 0.1), (4.0, 0.05), (16.0, 0.025), (8.0, 0.2)]  # (8, 0.2) is off the front
        self.assertEqual(bp.pareto(points), [(1.0, 0.1), (4.0, 0.05), (16.0, 0.025)])
        self.assertAlmostEqual(bp.time_to_error(points, 0.05), 4.0)
        # error ~ t^-1/2 between 4 and 16 s: 3% at 4 (5/3)^2 s
        self.assertAlmostEqual(bp.time_to_error(points, 0.03), 4.0 * (0.05 / 0.03) ** 2)
        self.assertAlmostEqual(bp.time_to_error(points, 0.2), 1.0)
        self.assertIsNone(bp.time_to_error(points, 0.01))


class Mask(unittest.TestCase):
    def test_compare_mask(self):
        h, w = 9, 9
        flags = np.full((h, w), float(bp.SINGLE_SURFACE))
        flags[4, 4] = bp.EMITTER | bp.SINGLE_SURFACE
        flags[0, 8] = 0  # an edge pixel
        objects = np.zeros((h, w))
        objects[8, 0] = bp.NO_SURFACE
        keep = bp.compared_pixels({"surface.flags": flags, "surface.object": objects}, 2)
        self.assertFalse(keep[2:7, 2:7].any(), "emitter and 2 px around it left out")
        self.assertTrue(keep[1, 1] and keep[7, 7] and keep[4, 1])
        self.assertFalse(keep[0:3, 6:9].any(), "2 px around the edge left out")
        self.assertFalse(keep[8, 0], "no surface")

    def test_relative_rmse_and_halves(self):
        rng = np.random.default_rng(1)
        truth = np.ones((64, 64, 3))
        halves = [truth + 0.1 * rng.standard_normal(truth.shape) for _ in range(2)]
        mask = np.ones((64, 64), bool)
        estimate = bp.relative_rmse(halves[0], halves[1], mask) / 2
        actual = bp.relative_rmse((halves[0] + halves[1]) / 2, truth, mask)
        self.assertAlmostEqual(estimate, actual, delta=0.03 * actual)


class OtherImages(unittest.TestCase):
    def test_each_image_is_reported_against_the_reference_per_object(self):
        # Object 0 (left half) 10% too bright, object 1 (right half) 20% too dark.
        ref = np.ones((4, 4, 3))
        objects = np.zeros((4, 4))
        objects[:, 2:] = 1
        rgb = ref.copy()
        rgb[:, :2] *= 1.1
        rgb[:, 2:] *= 0.8
        mask = np.ones((4, 4), bool)
        mask[0, 0] = False  # a left-out pixel counts nowhere
        whole, per = bp.against_reference("gpu-shoot (gpu/preview.exr)", rgb, ref, mask, objects, ["mirror", "floor"])
        # relative RMSE sqrt((7 x 0.01 + 8 x 0.04) / 15) over 15 pixels; signed (7 x 0.1 - 8 x 0.2) / 15
        self.assertIn(f"relative RMSE {100 * np.sqrt((7 * 0.01 + 8 * 0.04) / 15):.2f}%", whole)
        self.assertIn(f"mean signed error {100 * (7 * 0.1 - 8 * 0.2) / 15:+.2f}%", whole)
        self.assertTrue(whole.startswith("gpu-shoot (gpu/preview.exr) vs the Mitsuba reference"))
        self.assertEqual(per, "  per object: mirror +10.00%; floor -20.00%")

    def test_also_takes_name_equals_image(self):
        self.assertEqual(bp.named_image("gpu-shoot=out/x/gpu/preview.exr"), ("gpu-shoot", "out/x/gpu/preview.exr"))
        for bad in ("gpu-shoot", "=a.exr", "gpu="):
            with self.assertRaises(bp.argparse.ArgumentTypeError):
                bp.named_image(bad)


class BestRuns(unittest.TestCase):
    def test_most_accurate_run_per_series_and_its_surfaces(self):
        import tempfile
        with tempfile.TemporaryDirectory() as sweep:
            def report(solver, point, gather, rmse, means):
                d = os.path.join(sweep, "runs", solver, point, "rep0")
                os.makedirs(d, exist_ok=True)
                lines = [f'    "relative_rmse": {rmse},'] + [f'    "object[#{i}].mean_signed_error": {m},' for i, m in enumerate(means)]
                open(os.path.join(d, f"compare-{gather}.ron"), "w").write("(\n" + "\n".join(lines) + "\n)\n")
            report("hierarchical", "EPS=0.01", "full", 0.05, [-0.02, 0.01])
            report("hierarchical", "EPS=0.001", "full", 0.01, [-0.004, 0.003])
            report("hierarchical", "EPS=0.001", "preview", 0.03, [0.02, -0.01])
            best = bp.best_runs(sweep, ["floor", "ceiling"])
            self.assertEqual(sorted(best), ["hierarchical/full", "hierarchical/preview"])
            run, error, objects = best["hierarchical/full"]
            self.assertEqual(run, "EPS=0.001")
            self.assertEqual(error, 0.01)
            self.assertEqual(objects, [("floor", -0.004), ("ceiling", 0.003)])


class ReadSweep(unittest.TestCase):
    def test_series_label_points_by_their_knobs_only(self):
        import tempfile
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, "sweep.csv")
            open(path, "w").write(
                "solver,gather,EPS,cluster_s,solve_s,gather_s,total_s,total_min_s,total_max_s,error,error_min,error_max,"
                "worst_surface,worst_surface_min,worst_surface_max,pareto,reference\n"
                'hierarchical,preview,0.001,0.01,0.2,0.05,0.26,0.25,0.3,1.5e-2,1.4e-2,1.6e-2,5e-3,4e-3,7e-3,true,"ref"\n'
                'hierarchical,full,0.001,0.01,0.2,0.3,0.51,0.5,0.6,1.2e-2,1.1e-2,1.3e-2,,,,true,"ref"\n')
            series = bp.read_sweep(path)
            self.assertEqual(series["hierarchical/preview"], [(0.26, 0.015, "EPS=0.001")])
            self.assertEqual(series["hierarchical/full"], [(0.51, 0.012, "EPS=0.001")])


if __name__ == "__main__":
    unittest.main()
