"""The Vulkan backend from Python renders what the CPU backend renders. Without a Vulkan device
the test skips, or fails when RESOCT_REQUIRE_VULKAN=1 (as scripts/test.sh sets)."""
import os
import unittest

import numpy as np

import resoct


def vulkan_renderer(source, **options):
    try:
        return resoct.Renderer(source, "vulkan", **options)
    except resoct.Error as e:
        if e.code != "device":
            raise
        message = "no usable Vulkan device: " + str(e)
        if os.environ.get("RESOCT_REQUIRE_VULKAN") == "1":
            raise AssertionError("RESOCT_REQUIRE_VULKAN=1, but " + message) from e
        raise unittest.SkipTest(message) from e


class VulkanTest(unittest.TestCase):
    def test_matches_the_cpu_backend(self):
        source = resoct.open_source("procedural:tubes:64x64x64", brick=16)
        scene = resoct.overview_scene(source, width=96, height=80)
        gpu = vulkan_renderer(source, loader_threads=0)
        self.assertEqual(gpu.backend, "vulkan")
        cpu = resoct.Renderer(source, "cpu", loader_threads=0)
        a = cpu.render_until_converged(scene)
        b = gpu.render_until_converged(scene)
        self.assertTrue(a.converged and b.converged)
        self.assertEqual(a.frames, b.frames)
        self.assertGreater(a.image[:, :, :3].max(), 0.2)
        # The tolerance of the C++ oracle tests (tests/vulkan/vulkan_test_util.hpp).
        self.assertLess(np.abs(a.image - b.image).max(), 1e-4)
        self.assertEqual(a.stats["backend"]["samples"], b.stats["backend"]["samples"])


if __name__ == "__main__":
    unittest.main()
