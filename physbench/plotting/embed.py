"""Images inlined into HTML as ``data:`` URIs, so a report is one file that opens anywhere (mailed,
committed, moved away from its figure files). Called by the bench and discover reports."""

from __future__ import annotations

import base64
from pathlib import Path


def png_data_uri(png: bytes | Path) -> str:
    """``data:image/png;base64,...`` of PNG bytes or of a PNG file."""
    data = png.read_bytes() if isinstance(png, Path) else png
    return "data:image/png;base64," + base64.b64encode(data).decode("ascii")
