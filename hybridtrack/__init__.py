"""hybridtrack: weather-aware hybrid sun tracking for concentrating solar collectors."""

from .errors import HybridtrackError

__version__ = "0.1.0"

__all__ = ["HybridtrackError", "__version__"]
