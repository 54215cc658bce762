"""The tracking controller: what a PLC has and does, apart from the world it runs in.

Modules, one concern each: `config` (strategy and datasheet constants), `plan` (the computed
sun and working day from the controller's own clock), `observation` (one scan's readings),
`encoder`, `wind`, `skywatch`, `sensing` (the sensor gate and its `kalman` filter),
`calibration`, and `controller`, which puts them together scan by scan. Nothing here imports
the simulated world (`hybridtrack.world`, `hybridtrack.sky`, `hybridtrack.sensor`); a test
keeps it so.
"""

from .config import STRATEGIES, ControllerConfig
from .controller import Controller, ControllerOutputs
from .kalman import FastKalman, FilterpyKalman
from .modes import MODES, SENSOR_STATUS, SKY_CODES, TRACKING
from .observation import Observation
from .plan import CLOCK_STEP_SECONDS, ControllerPlan, MountEstimate, make_plan

__all__ = ["ControllerConfig", "STRATEGIES", "MODES", "SENSOR_STATUS", "SKY_CODES", "TRACKING", "FastKalman",
           "FilterpyKalman", "Controller", "ControllerOutputs", "Observation", "ControllerPlan", "MountEstimate",
           "make_plan", "CLOCK_STEP_SECONDS"]
