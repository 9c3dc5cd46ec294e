"""Loading the repository's scripts (``sweeps/``, ``benchmarks/``) as modules in tests; they are
files, not part of the package."""
import ast
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


def import_what_it_imports(code: str, where: str) -> None:
    """Run only the import statements of ``code`` (Python source; ``where`` names it in errors):
    the default tier's check that a document's snippet or a notebook's cell still parses and
    finds every name it imports, without running it."""
    tree = ast.parse(code, filename=where)
    imports = [node for node in ast.walk(tree) if isinstance(node, (ast.Import, ast.ImportFrom))]
    exec(compile(ast.Module(body=imports, type_ignores=[]), where, "exec"), {})
