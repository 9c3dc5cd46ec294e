"""Parameter sweeps: specs as TOML data (``spec``, their map entries resolved by
:mod:`jaxswarm.maps.entry`), a swarm's runs as compiled batches over the devices (``batches``),
the resumable runner (``runner``), the Parquet results store (``store``), the run record a table
row carries (``run_record``) and replaying a row alone (``replay``)."""
from jaxswarm.sweep.batches import SUCCESS_GAP
from jaxswarm.sweep.runner import default_out, run_sweep
from jaxswarm.sweep.spec import SpecError, SweepSpec, load_spec, spec_from_dict
from jaxswarm.sweep.store import ResultsStore, StoreMismatchError, read_results

__all__ = ["SUCCESS_GAP", "ResultsStore", "SpecError", "StoreMismatchError", "SweepSpec",
           "default_out", "load_spec", "read_results", "run_sweep", "spec_from_dict"]
