"""Where worlds come from: :mod:`~jaxswarm.maps.paper` (the RFD paper's maze, mosaic and alley
maps), :mod:`~jaxswarm.maps.random` (seeded random grids and thin-wall path maps),
:mod:`~jaxswarm.maps.movingai` (Moving AI ``.map``/``.scen`` files),
:mod:`~jaxswarm.maps.iwd_pg` (the IWD_PG experiments' maps) and :mod:`~jaxswarm.maps.planes`
(the bees' planes of rectangles)."""
