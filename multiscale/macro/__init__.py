"""Macro scale (DOLFINx): two deformable bodies coupled through a flat contact interface.

``geometry`` (builder specs, no DOLFINx), ``mesh`` (two-body mesh, interface measure and per-facet
fields), ``interface`` (penalty/law contact, friction, frictional heat), ``mechanics``, ``thermal``
and ``runner`` (a scene's staggered thermo-mechanical run, thesis Fig. 7.4). Importing this package
does not import DOLFINx; its submodules do.
"""
