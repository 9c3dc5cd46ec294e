"""Write the ``README.md`` index of a results folder from the provenance records of its tables.

Run from the repository root after the table scripts (``make reproduce`` does)::

    python sweeps/index_results.py results
"""
from jaxswarm.studies.provenance import main

if __name__ == "__main__":
    raise SystemExit(main())
