"""What the table scripts of ``sweeps/`` share, and the papers' tables they reproduce, one idea a
module:

* :mod:`~jaxswarm.studies.provenance`: the provenance record of every table, and the index of a
  results folder;
* :mod:`~jaxswarm.studies.arguments`: the command-line checks (counts, lists, ``--out``);
* :mod:`~jaxswarm.studies.problems`: a named map with its task and its optimum;
* :mod:`~jaxswarm.studies.timing`: compile once, then time each run alone;
* :mod:`~jaxswarm.studies.success`: when a run reaches the optimum;
* :mod:`~jaxswarm.studies.figures`: grids of map panels, written as PNG files;
* :mod:`~jaxswarm.studies.rfd_table1`: the rows of the RFD paper's Table 1, which three scripts
  run;
* :mod:`~jaxswarm.studies.rfd_dynamic`: the RFD paper's dynamic scenarios (its Tables 2-5) on our
  rebuilds of its maps.
"""
