"""Figures of the package, one module per results family (matplotlib, Agg backend); solver and
workflow modules never draw. Only rank 0 calls these."""
