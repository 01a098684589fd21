"""Figures (matplotlib): imported only where figures are drawn."""
