"""inksim: open, label and plot inksim results; run the inksim CLI."""

from .result import Result, open_result
from .study import Study, open_study
from .formulation import MatchResult, FitResult, open_match, open_fit
from .plot import plot_spectra, plot_brdf, show_tile, brdf_in_plane, brdf_on_grid

__version__ = "0.1.0"
from .cli import InksimError, InksimNotFound, RunOutput, find_binary, run

__all__ = [
    "open_result", "Result", "open_study", "Study",
    "open_match", "MatchResult", "open_fit", "FitResult",
    "plot_spectra", "plot_brdf", "show_tile", "brdf_in_plane", "brdf_on_grid",
    "run", "find_binary", "RunOutput", "InksimError", "InksimNotFound",
]
