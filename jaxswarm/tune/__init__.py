"""Tuning a swarm's open constants: a spec (:mod:`.spec`) names the search space (:mod:`.space`),
training and held-out instances, a budget of runs, an objective and a method: iterated racing
(:mod:`.race`, with the Friedman test and Conover's post-hoc of :mod:`.stats`), random search,
the grid or evolution strategies (:mod:`.search`); every run goes through the swarm's compiled
batches into a resumable store (:mod:`.evaluate`), and :func:`tune` rescores the best settings
beside the defaults on the held-out instances (:mod:`.tuner`)."""
from jaxswarm.tune.spec import TuneSpec, TuneSpecError, load_tune_spec, tune_spec_from_dict
from jaxswarm.tune.tuner import TuneResult, default_tune_out, tune

__all__ = ["TuneResult", "TuneSpec", "TuneSpecError", "default_tune_out", "load_tune_spec",
           "tune", "tune_spec_from_dict"]
