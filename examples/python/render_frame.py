import resoct

source = resoct.open_source("procedural:tubes:128x128x128")
renderer = resoct.Renderer(source, "cpu")
scene = resoct.overview_scene(source, width=256, height=256)
scene.orbit(30)  # degrees about the camera's up axis

frame = renderer.render_until_converged(scene)
print(frame.image.shape, frame.converged, frame.stats["samples_per_ray"])
resoct.write_png(frame.image, "frame.png")

# A scene is also a dict in the scene JSON format (docs/scene.md).
tf = [[0.0, 0, 0, 0, 0], [0.3, 1.0, 0.6, 0.2, 0.25], [1.0, 1.0, 1.0, 0.8, 0.8]]
mip = renderer.render_until_converged({
    "camera": {"eye": [1.8, 1.1, 1.6], "target": [0.5, 0.5, 0.5]},
    "viewport": {"width": 256, "height": 256},
    "channels": [{"channel": 0, "tf": tf, "mode": "mip"}],
})
assert frame.converged and mip.converged
