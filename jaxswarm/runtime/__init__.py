"""How jaxswarm runs: arithmetic whose result does not depend on the batch
(:mod:`~jaxswarm.runtime.arithmetic`), XLA:CPU devices and threads
(:mod:`~jaxswarm.runtime.cpu`), compiled programs kept between processes
(:mod:`~jaxswarm.runtime.cache`) and let go when a process holds too many
(:mod:`~jaxswarm.runtime.programs`), files written whole or not at all
(:mod:`~jaxswarm.runtime.atomic`), one writing process per folder (:mod:`~jaxswarm.runtime.lock`),
a vmap rule for loops whose trip count differs between
batch members (:mod:`~jaxswarm.runtime.batching`) and a Config's options checked against their
annotations (:mod:`~jaxswarm.runtime.options`)."""
