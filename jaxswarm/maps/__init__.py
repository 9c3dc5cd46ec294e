"""Where maps come from: ``paper`` (the RFD paper's maze/mosaic/alley maps), ``random`` (seeded
random grids and thin-wall path maps), ``movingai`` (Moving AI ``.map``/``.scen`` files),
``iwd_pg`` (the IWD_PG experiments' maps) and ``plane`` (planes of rectangles for the bees)."""
