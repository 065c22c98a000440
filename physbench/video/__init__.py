"""From a camera's video to the scene's metres. So far: reading and writing video with container
timestamps (:mod:`~physbench.video.reader`, :mod:`~physbench.video.writer`, PyAV: ``pip install
physbench[video]``) and calibration, pixels to metres on the plane of motion
(:mod:`~physbench.video.calibration`)."""
