"""hybridtrack: weather-aware hybrid sun tracking for concentrating solar collectors."""

from .errors import HybridtrackError

__version__ = "0.1.0"

__all__ = ["HybridtrackError", "simulate", "simulate_field", "__version__"]


def __getattr__(name: str):
    # the simulator pulls in pvlib, scikit-fuzzy and filterpy; load it on first use only
    if name == "simulate":
        from .simulation import simulate

        return simulate
    if name == "simulate_field":
        from .fields import simulate_field

        return simulate_field
    raise AttributeError(f"module 'hybridtrack' has no attribute {name!r}")
