"""What a rough surface is: spectral moments, spectra, height maps, readers and analysis.

Modules:
    moments      :class:`SpectralMoments` (paper sections 2 and 5: bandwidths, summit density,
                 summit curvature and height statistics, plasticity index), the summit pdf
                 :func:`psum`, :class:`MomentTensor` (moments in any axes, grain angle) and the
                 moments of a sampled height map.
    spectrum     a Gaussian spectrum fitted to five moments (:func:`fit_spectrum`) and its
                 periodic realisations (inputs of the BEM law, :mod:`rough_contact.micro.bem`).
    topography   measured maps: :class:`HeightMap`, readers/writers, detrending, synthetic maps
                 with a given PSD, :func:`analyze` (moments in the grain axes + model advice).

Height-map arrays. Every function here that computes from a bare array takes it as
``z[i, j]`` at ``x = i dx, y = j dy`` — shape ``(nx, ny)``, axis 0 along x (the grain) — with
heights and steps in one length unit (mm throughout the BEM and the statistical layers; the
moment functions take a ``unit=`` argument). :class:`HeightMap` is the measured-data container:
it keeps the file's image layout ``(ny, nx)`` (row = y) and unit, and hands the package
convention over through :meth:`HeightMap.moments` (``heights.T`` in mm).

Units: the package works in mm, N, MPa; spectral moments are accepted in the paper's
micrometre convention at the API boundary (``unit="um"``) and stored in mm.
Pure layer: numpy and scipy only.
"""

from .moments import (ANISOTROPY_WARN_RATIO, MOMENT_ORDERS, WINDOWS, MomentTensor,
                      SpectralMoments, moment_tensor_from_height_map, moments_from_height_map,
                      plasticity_index, psum)
from .spectrum import SpectrumShape, StretchedSpectrum, example_surfaces, fit_spectrum
from .topography import (DETRENDS, LENGTH_UNITS, MAX_PLAUSIBLE_RMS_SLOPE, MIN_PIXELS,
                         MIN_PLAUSIBLE_CURVATURE_RADIUS, AnisotropicGaussianPSD, HeightMap,
                         ModelAdvice, PowerSpectrum, SurfaceAnalysis, analyze,
                         check_units_plausible, detrend,
                         model_advice, read_height_map, read_instrument, read_npy,
                         read_text_grid, read_xyz, synthetic_height_map, write_height_map,
                         write_npy, write_text_grid, write_xyz)

__all__ = [
    "ANISOTROPY_WARN_RATIO", "MOMENT_ORDERS", "WINDOWS", "MomentTensor", "SpectralMoments",
    "moment_tensor_from_height_map", "moments_from_height_map", "plasticity_index", "psum",
    "SpectrumShape", "StretchedSpectrum", "example_surfaces", "fit_spectrum",
    "DETRENDS", "LENGTH_UNITS", "MIN_PIXELS", "MAX_PLAUSIBLE_RMS_SLOPE",
    "MIN_PLAUSIBLE_CURVATURE_RADIUS", "check_units_plausible", "AnisotropicGaussianPSD",
    "HeightMap",
    "ModelAdvice", "PowerSpectrum", "SurfaceAnalysis", "analyze", "detrend", "model_advice",
    "read_height_map", "read_instrument", "read_npy", "read_text_grid", "read_xyz",
    "synthetic_height_map", "write_height_map", "write_npy", "write_text_grid", "write_xyz",
]
