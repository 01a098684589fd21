"""Figures of the package, one module per results family (matplotlib ``Figure`` objects, no pyplot
state); solver, workflow and study modules never draw. Only rank 0 calls these."""
