"""From a camera's video to the scene's metres: reading and writing video with container
timestamps (:mod:`~physbench.video.reader`, :mod:`~physbench.video.writer`, PyAV: ``pip install
physbench[video]``), calibration, pixels to metres on the plane of motion
(:mod:`~physbench.calibration`), tracking the scene's bodies into a recording
(:mod:`~physbench.video.background`, :mod:`~physbench.video.detect`,
:mod:`~physbench.video.track`, pictures in :mod:`~physbench.video.overlay`; ``physbench track``),
per-body masks for the correction loop (:mod:`~physbench.video.segment`,
:mod:`~physbench.video.footage`), and scoring a tracker against known motion
(:mod:`~physbench.video.accuracy`)."""
