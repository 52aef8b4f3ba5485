"""Finite-element basics: shape functions and Gauss rules."""

from .quadrature import default_rule, gauss_1d, gauss_hex, gauss_quad, gauss_tensor
from .shapes import DIM, IDX, NNODES, NODES, ORDER, eval_shape, eval_surface, shape_functions

__all__ = [
    "DIM", "IDX", "NNODES", "NODES", "ORDER", "default_rule", "eval_shape", "eval_surface",
    "gauss_1d", "gauss_hex", "gauss_quad", "gauss_tensor", "shape_functions",
]
