"""Where generated files go: everything under the repository's ``build/``."""

import os
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
BUILD = Path(os.environ.get("DMD_BUILD_DIR", ROOT / "build"))


def build_dir(*parts):
    path = BUILD.joinpath(*parts)
    path.mkdir(parents=True, exist_ok=True)
    return path


def slug(text):
    """A file-name-safe form of a test id such as ``test_x[dlp7000-8]``."""
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", text).strip("_")
