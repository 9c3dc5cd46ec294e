"""Started with every Python process a test starts (the compile ledger puts this folder on
``PYTHONPATH``): when ``$JAXSWARM_LEDGER_OUT`` names a folder, the programs the process builds
(:mod:`program_hooks`) are written there as ``<pid>.json`` when it exits, for the test that
started it to count."""
import os

import program_hooks

if os.environ.get(program_hooks.OUT_VARIABLE):
    import atexit
    import json

    _built: dict[str, list] = {}

    def _record(fingerprint, name, seconds):
        _built.setdefault(fingerprint, [name, 0.0])[1] += seconds

    def _write(folder=os.environ[program_hooks.OUT_VARIABLE]):
        if _built and os.path.isdir(folder):
            with open(os.path.join(folder, f"{os.getpid()}.json"), "w") as out:
                json.dump(_built, out)

    program_hooks.install(_record)
    atexit.register(_write)
