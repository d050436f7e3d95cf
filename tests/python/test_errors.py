"""Library errors arrive as resoct.Error carrying the library's message (which names the
parameter, path or JSON field) and its code."""
import unittest

import numpy as np

import resoct


class ErrorTest(unittest.TestCase):
    def assert_error(self, code, fragment, fn, *args, **kwargs):
        with self.assertRaises(resoct.Error) as caught:
            fn(*args, **kwargs)
        self.assertEqual(caught.exception.code, code)
        self.assertIn(fragment, str(caught.exception))
        return caught.exception

    def test_is_a_runtime_error(self):
        self.assertTrue(issubclass(resoct.Error, RuntimeError))

    def test_missing_source_names_the_path(self):
        self.assert_error("io", "/no/such/volume.rbs", resoct.open_source, "/no/such/volume.rbs")

    def test_bad_procedural_spec(self):
        self.assert_error("invalid_argument", "nosuchshape", resoct.open_source,
                          "procedural:nosuchshape")

    def test_bad_options_name_the_parameter(self):
        source = resoct.open_source("procedural:sphere:32x32x32")
        self.assert_error("invalid_argument", "parameter 'mode'", resoct.Renderer, source,
                          mode="raycast")
        self.assert_error("invalid_argument", "parameter 'strategy'", resoct.Renderer, source,
                          strategy="lazy")
        self.assert_error("invalid_argument", "parameter 'host_eviction'", resoct.Renderer,
                          source, host_eviction="fifo")
        self.assert_error("invalid_argument", "parameter 'output'", resoct.Renderer, source,
                          output="rgb")
        self.assert_error("invalid_argument", "GPU memory", resoct.Renderer, source,
                          output="device")
        self.assert_error("invalid_argument", "parameter 'device_cache_mb'", resoct.Renderer,
                          source, device_cache_mb=0)
        self.assert_error("invalid_argument", "parameter 'backend'", resoct.Renderer, source,
                          "opengl")
        self.assert_error("invalid_argument", "parameter 'brick_size'", resoct.open_source,
                          "procedural:sphere:32x32x32", brick=2)
        self.assert_error("invalid_argument", "parameter 'channel'", source.value_range, 3)

    def test_bad_scene_dict_names_the_json_path(self):
        source = resoct.open_source("procedural:sphere:32x32x32")
        renderer = resoct.Renderer(source, loader_threads=0)
        scene = {
            "camera": {"eye": [2, 0.5, 0.5], "target": [0.5, 0.5, 0.5]},
            "channels": [{"channel": 0, "tf": [[0.0, 0, 0, 0, 0], [1.0, 1, 1, 1, 1.3]]}],
        }
        self.assert_error("invalid_argument", "scene: channels[0].tf[1]", renderer.render_frame,
                          scene)
        scene["channels"][0]["tf"][1][4] = 0.5
        scene["camera"]["eyes"] = [1, 1, 1]
        self.assert_error("invalid_argument", "camera.eyes: unknown key", resoct.Scene, scene)
        del scene["camera"]["eyes"]
        scene["channels"][0]["channel"] = 4
        self.assert_error("invalid_argument", "scene", renderer.render_frame, scene)

    def test_bad_arrays(self):
        self.assert_error("invalid_argument", "parameter 'array'", resoct.from_array,
                          np.zeros((4, 4), dtype=np.uint8))
        self.assert_error("invalid_argument", "int64", resoct.from_array,
                          np.zeros((8, 8, 8), dtype=np.int64))
        self.assert_error("invalid_argument", "parameter 'image'", resoct.write_png,
                          np.zeros((4, 4, 3), dtype=np.uint8), "/tmp/never-written.png")

    def test_scene_of_the_wrong_type(self):
        source = resoct.open_source("procedural:sphere:32x32x32")
        renderer = resoct.Renderer(source, loader_threads=0)
        self.assert_error("invalid_argument", "parameter 'scene'", renderer.render_frame, 42)


if __name__ == "__main__":
    unittest.main()
