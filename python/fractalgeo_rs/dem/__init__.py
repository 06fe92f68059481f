"""DEM tools: shaded relief, lakes and coastlines, synthetic DEMs."""
from fractalgeo_rs.dem._hillshade import hillshade, metres_per_degree, shade_to_byte
from fractalgeo_rs.dem._lakes import Lakes, lakes

__all__ = ["hillshade", "shade_to_byte", "metres_per_degree", "lakes", "Lakes"]
