"""What the table scripts of ``sweeps/`` share: provenance records of every table
(:mod:`~jaxswarm.studies.provenance`)."""
