"""multiscale: multi-scale thermo-mechanics of rough frictional sliding contacts.

Micro scale (``multiscale.micro``): rough surfaces, FFT-BEM and asperity contact, wear,
conduction, frictional heating. Macro scale (``multiscale.macro``, DOLFINx): pin-on-disc and
disc-brake models whose flat interfaces carry homogenized per-facet laws.
SI units everywhere (m, Pa, W, K, s).
"""
from multiscale.errors import ConvergenceError, InputError, MultiscaleError, OutputError, SceneError

__version__ = "0.1.0"
__all__ = ["ConvergenceError", "InputError", "MultiscaleError", "OutputError", "SceneError", "__version__"]
