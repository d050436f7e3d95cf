"""Rendering from Python: the same pixels as the C++ example, progress from a cold cache, the
8-bit and float outputs, and the frame statistics."""
import os
import unittest

import numpy as np

import resoct

TUBES = "procedural:tubes:128x128x128"


class RenderTest(unittest.TestCase):
    def test_same_image_as_the_cpp_example(self):
        # examples/02_render_frame.cpp renders this source's overview scene until converged with
        # the default options and writes it to RESOCT_EXAMPLE_FRAME.
        expected = resoct.read_png(os.environ["RESOCT_EXAMPLE_FRAME"])
        source = resoct.open_source(TUBES)
        renderer = resoct.Renderer(source, "cpu", output="both")
        frame = renderer.render_until_converged(resoct.overview_scene(source))
        self.assertTrue(frame.converged)
        self.assertEqual(frame.rgba8.shape, (512, 512, 4))
        self.assertEqual(frame.rgba8.dtype, np.uint8)
        np.testing.assert_array_equal(frame.rgba8, expected)
        # The float image is the 8-bit one before rounding.
        self.assertEqual(frame.image.dtype, np.float32)
        rounded = np.round(np.clip(frame.image, 0.0, 1.0) * 255.0).astype(np.uint8)
        np.testing.assert_array_equal(rounded, frame.rgba8)
        # Not a blank frame.
        lit = np.count_nonzero(frame.rgba8[:, :, :3].max(axis=2) > 20)
        self.assertGreater(lit, 512 * 512 // 20)

    def test_cold_cache_progresses_to_convergence(self):
        source = resoct.open_source(TUBES)
        renderer = resoct.Renderer(source, loader_threads=0)
        scene = resoct.overview_scene(source, width=128, height=96)
        first = renderer.render_frame(scene)
        self.assertFalse(first.converged)
        self.assertGreater(first.stats["brick_requests"], 0)
        self.assertEqual(first.frames, 1)
        self.assertEqual(renderer.frame_index, 1)
        last = renderer.render_until_converged(scene, max_frames=100)
        self.assertTrue(last.converged)
        self.assertGreater(last.frames, 1)
        self.assertEqual(renderer.frame_index, 1 + last.frames)
        stats = last.stats
        self.assertEqual(stats["backend"]["rays"], 128 * 96)
        self.assertGreater(stats["samples_per_ray"], 1.0)
        self.assertEqual(stats["backend"]["cap_hits"], 0)
        self.assertEqual(stats["brick_requests"], 0)
        self.assertGreater(stats["resident_bricks"], 0)
        self.assertEqual(last.failures, [])
        self.assertEqual(last.image.shape, (96, 128, 4))
        self.assertIsNone(last.rgba8)  # output="rgba32f" by default

    def test_rgba8_output_and_arrays_outlive_their_frame(self):
        source = resoct.open_source(TUBES)
        scene = resoct.overview_scene(source, width=64, height=64)
        floats = resoct.Renderer(source, loader_threads=0)
        bytes8 = resoct.Renderer(source, loader_threads=0, output="rgba8")
        a = floats.render_until_converged(scene).image
        b = bytes8.render_until_converged(scene)
        self.assertIsNone(b.image)
        pixels = b.rgba8
        del b  # the array keeps the frame's buffer alive
        expected = np.round(np.clip(a, 0.0, 1.0) * 255.0).astype(np.uint8)
        np.testing.assert_array_equal(pixels, expected)

    def test_orbiting_changes_the_view(self):
        source = resoct.open_source(TUBES)
        renderer = resoct.Renderer(source, loader_threads=0)
        scene = resoct.overview_scene(source, width=64, height=64)
        before = renderer.render_until_converged(scene).image.copy()
        scene.orbit(90)
        after = renderer.render_until_converged(scene)
        self.assertTrue(after.converged)
        self.assertGreater(np.abs(after.image - before).max(), 0.1)

    def test_error_bounded_lod_needs_measured_errors(self):
        source = resoct.open_source("procedural:sphere:48x48x48")
        scene = resoct.overview_scene(source, width=48, height=48).to_dict()
        scene["lod_error_color"] = 0.5
        with self.assertRaises(resoct.Error) as caught:
            resoct.Renderer(source, loader_threads=0).render_frame(scene)
        self.assertIn("lod_error_color", str(caught.exception))
        # With measured errors a coarse colour error converges on fewer bricks than the footprint.
        eb = resoct.Renderer(source, loader_threads=0, brick_errors=True)
        last = eb.render_until_converged(scene)
        self.assertTrue(last.converged)
        del scene["lod_error_color"]
        plain = resoct.Renderer(source, loader_threads=0).render_until_converged(scene)
        self.assertLess(last.stats["resident_bricks"], plain.stats["resident_bricks"])

    def test_png_round_trip(self):
        image = np.zeros((3, 5, 4), dtype=np.float32)
        image[1, 2] = (1.0, 0.5, 0.0, 1.0)
        path = os.path.join(os.environ.get("TMPDIR", "/tmp"), f"resoct-py-{os.getpid()}.png")
        try:
            resoct.write_png(image, path)
            back = resoct.read_png(path)
        finally:
            if os.path.exists(path):
                os.remove(path)
        self.assertEqual(back.shape, (3, 5, 4))
        self.assertEqual(tuple(back[1, 2]), (255, 128, 0, 255))
        self.assertEqual(int(back.sum()), 255 + 128 + 255)


if __name__ == "__main__":
    unittest.main()
