"""The value parsers several scene tables share, one plausible range each (``multiscale.schema``):
a friction coefficient, a load face's pressure, an angular speed and an RMS roughness read the same
in [loading], [interfaces.<name>], [loading.stribeck], [stability.sweep] and [roughness] (the RMS
roughness in the studies' micro problems too). A value outside its range is warned, not refused
(``multiscale check --keys`` lists the ranges)."""
from __future__ import annotations

from multiscale.schema import Quantity

HOTTEST = 2500.0     # K, the top of the plausible temperatures (molten iron), of inputs and results
TEMPERATURE = Quantity("temperature", gt=0, plausible=(20.0, HOTTEST))    # cryogenic to molten iron
MU = Quantity("dimensionless", ge=0, plausible=(0.0, 2.0))        # a friction coefficient
LOAD_PRESSURE = Quantity("pressure", gt=0, plausible=(1e3, 2e8))        # on load faces: 0.01 to 2000 bar
ANGULAR_SPEED = Quantity("angular_speed", ge=0, plausible=(0.0, 2500.0),   # up to ~24 000 rpm
                         outside="a speed about geometry.axis; to turn the other way, give the opposite axis")
ROUGHNESS = Quantity("length", gt=0, plausible=(1e-10, 1e-3))            # RMS height
