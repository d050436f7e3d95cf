"""Scenes from dicts, JSON and files; the camera properties a viewer loop changes."""
import json
import math
import os
import tempfile
import unittest

import numpy as np

import resoct

SOURCE_DIR = os.environ["RESOCT_SOURCE_DIR"]


class SceneTest(unittest.TestCase):
    def test_dict_round_trip_and_defaults(self):
        d = {
            "camera": {"eye": [1.8, 1.1, 1.6], "target": [0.5, 0.5, 0.5]},
            "viewport": {"width": 64, "height": 48},
            "channels": [{"channel": 0, "tf": [[0.0, 0, 0, 0, 0], [1.0, 1, 1, 1, 0.5]]}],
        }
        scene = resoct.Scene.from_dict(d)
        self.assertEqual((scene.width, scene.height), (64, 48))
        self.assertEqual(scene.eye, (1.8, 1.1, 1.6))
        full = scene.to_dict()
        self.assertEqual(full["camera"]["up"], [0.0, 1.0, 0.0])  # defaults filled in
        self.assertEqual(full["ert_opacity"], 0.99)
        self.assertEqual(resoct.Scene(full), scene)
        self.assertEqual(resoct.Scene.from_json(json.dumps(full)), scene)

    def test_numpy_values_are_accepted(self):
        d = {
            "camera": {"eye": np.array([1.8, 1.1, 1.6]), "target": [np.float32(0.5)] * 3},
            "channels": [{"channel": 0, "tf": np.array([[0.0, 0, 0, 0, 0], [1.0, 1, 1, 1, 0.5]])}],
        }
        self.assertEqual(resoct.Scene(d).target, (0.5, 0.5, 0.5))

    def test_load_and_save_match_the_tools(self):
        scene = resoct.Scene.load(os.path.join(SOURCE_DIR, "examples/scenes/tubes.json"))
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "scene.json")
            scene.save(path)
            self.assertEqual(resoct.Scene.load(path), scene)

    def test_dict_and_scene_render_alike(self):
        source = resoct.open_source("procedural:sphere:32x32x32")
        scene = resoct.overview_scene(source, width=32, height=32)
        a = resoct.Renderer(source, loader_threads=0).render_until_converged(scene)
        b = resoct.Renderer(source, loader_threads=0).render_until_converged(scene.to_dict())
        self.assertTrue(a.converged and b.converged)
        np.testing.assert_array_equal(a.image, b.image)

    def test_overview_and_orbit(self):
        source = resoct.open_source("procedural:cells:64x64x16")
        scene = resoct.overview_scene(source, width=300, height=200)
        self.assertEqual((scene.width, scene.height), (300, 200))
        self.assertEqual(len(scene.to_dict()["channels"]), 4)
        eye, target = np.array(scene.eye), np.array(scene.target)
        scene.orbit(90)
        turned = np.array(scene.eye)
        self.assertAlmostEqual(np.linalg.norm(turned - target), np.linalg.norm(eye - target))
        self.assertAlmostEqual(turned[1], eye[1])
        # A quarter turn about +y: the horizontal parts of the offsets are perpendicular.
        flat, turned_flat = (eye - target)[[0, 2]], (turned - target)[[0, 2]]
        self.assertAlmostEqual(float(np.dot(flat, turned_flat)), 0.0, places=9)
        scene.eye = (2.0, 0.5, 0.5)
        self.assertEqual(scene.eye, (2.0, 0.5, 0.5))
        self.assertIsNone(scene.timepoint)
        scene.timepoint = 0
        self.assertEqual(scene.timepoint, 0)


class SourceTest(unittest.TestCase):
    def test_metadata(self):
        source = resoct.open_source("procedural:cells:64x48x16:17", brick=16)
        self.assertEqual(source.extent, (64, 48, 16))
        self.assertEqual(source.channels, 17)
        self.assertEqual(source.dtype, "u16")
        self.assertGreater(source.levels, 1)
        self.assertEqual(source.timepoints, 1)
        lo, hi = source.data_range(1)
        self.assertLessEqual(lo, hi)
        self.assertIn("64x48x16", repr(source))

    def test_array_source_renders_the_array(self):
        z, y, x = np.mgrid[0:40, 0:40, 0:40]
        ball = ((x - 20.0) ** 2 + (y - 20.0) ** 2 + (z - 20.0) ** 2 < 15.0 ** 2)
        volume = np.stack([ball * 200, ball[::-1] * 0]).astype(np.uint8)  # channel 1 all zero
        source = resoct.from_array(volume, spacing=(1.0, 1.0, 2.0), brick=16)
        self.assertEqual(source.extent, (40, 40, 40))
        self.assertEqual(source.spacing, (1.0, 1.0, 2.0))
        self.assertEqual(source.channels, 2)
        self.assertEqual(source.data_range(0), (0.0, 200.0))
        self.assertEqual(source.data_range(1), (0.0, 0.0))
        renderer = resoct.Renderer(source, loader_threads=0)
        frame = renderer.render_until_converged(resoct.overview_scene(source, width=64, height=64))
        self.assertTrue(frame.converged)
        # The ball is in the middle of the view, the corners show the background.
        self.assertGreater(frame.image[32, 32, :3].max(), 0.2)
        self.assertEqual(frame.image[0, 0, :3].max(), 0.0)

    def test_float_arrays_take_their_data_range(self):
        data = np.linspace(-3.0, 5.0, 16 * 16 * 16, dtype=np.float32).reshape(16, 16, 16)
        data[8, 8, 8] = math.nan  # left out of the range
        source = resoct.from_array(data, brick=8)
        self.assertEqual(source.dtype, "f32")
        self.assertEqual(source.value_range(0), (-3.0, 5.0))
        fixed = resoct.from_array(data, value_range=(0.0, 1.0), brick=8)
        self.assertEqual(fixed.value_range(0), (0.0, 1.0))


if __name__ == "__main__":
    unittest.main()
