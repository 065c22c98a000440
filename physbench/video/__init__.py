"""From a camera's video to the scene's metres. So far: calibration (pixels to metres on the plane
of motion, :mod:`~physbench.video.calibration`)."""
