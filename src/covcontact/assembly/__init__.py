"""Assembly: the node-structured sparsity pattern and race-free scatter into CSR data."""

from .pattern import Pattern, scatter_matrices, scatter_vectors

__all__ = ["Pattern", "scatter_matrices", "scatter_vectors"]
