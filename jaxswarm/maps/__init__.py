"""Where maps come from: ``paper`` (the RFD paper's maze/mosaic/alley maps), ``random`` (seeded
random grids and thin-wall path maps) and ``movingai`` (Moving AI ``.map``/``.scen`` files)."""
