"""Control: movement primitives and their execution on a simulated arm."""

from skmotion.control._arm import ArmModel
from skmotion.control._primitives import KMeansPrimitiveController
from skmotion.control._simulate import ArmSimulation, simulate_arm

__all__ = ["ArmModel", "ArmSimulation", "KMeansPrimitiveController", "simulate_arm"]
