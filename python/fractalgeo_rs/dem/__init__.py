"""DEM tools: shaded relief, lakes and coastlines, fractal resampling."""
from fractalgeo_rs.dem._hillshade import hillshade, metres_per_degree, shade_to_byte
from fractalgeo_rs.dem._lakes import Lakes, lakes
from fractalgeo_rs.dem._resample import HURST_RANGE, ResampleAnalysis, resample_analysis
from fractalgeo_rs.dem._resample_api import fractal_resample

__all__ = ["hillshade", "shade_to_byte", "metres_per_degree", "lakes", "Lakes", "fractal_resample", "resample_analysis",
           "ResampleAnalysis", "HURST_RANGE"]
