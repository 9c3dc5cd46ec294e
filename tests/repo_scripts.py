"""Loading the repository's scripts (``sweeps/``, ``benchmarks/``) as modules in tests; they are
files, not part of the package."""
import importlib.util
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def load_script(relative: str):
    """The script at ``ROOT / relative`` (e.g. ``"sweeps/rfd_static.py"``), imported as a module
    named after its file."""
    path = ROOT / relative
    spec = importlib.util.spec_from_file_location(path.stem, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module
