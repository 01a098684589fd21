"""Analytic reference solutions: closed forms of contact, heat and stability problems.

Small pure functions (numpy/scipy only), each citing the paper or thesis equation it implements.
The solvers of ``multiscale.micro`` and ``multiscale.macro`` may import them; this package imports
nothing from the solvers. Modules: ``hertz`` (sphere and ellipsoid on a flat), ``love`` (uniform
pressure on a rectangle or triangle), ``westergaard`` (sinusoidal contact), ``layered`` (one elastic
layer), ``conduction`` (constriction and layered steady conduction), ``heat`` (heat sources),
``thermal`` (cooling by convection and radiation, a slab with convection, conduction with kappa(T))
and ``stability`` (Hoffmann's 2-DOF mode-coupling model).
"""
