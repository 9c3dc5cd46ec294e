"""Where worlds come from: :mod:`~jaxswarm.maps.paper` (the RFD paper's maze, mosaic and alley
maps), :mod:`~jaxswarm.maps.random` (seeded random grids and thin-wall path maps),
:mod:`~jaxswarm.maps.movingai` (Moving AI ``.map``/``.scen`` files),
:mod:`~jaxswarm.maps.iwd_pg` (the IWD_PG experiments' maps) and :mod:`~jaxswarm.maps.planes`
(the bees' planes of rectangles); :mod:`~jaxswarm.maps.entry` resolves a map entry to a world,
a task and its optimum."""
