"""Blender metaballs as the paper's free forms: pure math, no bpy (docs/blender.md, "Metaballs").

Blender's field of a metaball family is the sum over its elements of s * max(1 - |d|^2 / R^2, 0)^3,
d the point in the element's frame (divided by the element's size for an ellipsoid), and the
surface lies where the sum equals the threshold. That is F = -threshold + sum s_i * max(Q_i, 0)^3:
a constant base quadric and one quadric Q_i per element, the free form of paper eq. 1-2.
"""
import math

import numpy as np

# Blender clamps an element's stiffness to this before it sums the field.
MAX_STIFFNESS = 10.0

# Elements whose field is a clamped distance, not a quadric: the axes each one stretches.
_STRETCHED_AXES = {"CAPSULE": (0,), "PLANE": (0, 1), "CUBE": (0, 1, 2)}


def quaternion_matrix(w, x, y, z):
    """The rotation of a quaternion (w, x, y, z) as Blender applies it, without normalising."""
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
    ], dtype=np.float64)


def element_matrix(object_matrix, co, rotation):
    """World from element frame: the object's 4x4 world matrix, then the element's translation
    `co` and rotation (w, x, y, z)."""
    local = np.eye(4)
    local[:3, :3] = quaternion_matrix(*rotation)
    local[:3, 3] = co
    return np.asarray(object_matrix, dtype=np.float64) @ local


def element_axes(kind, radius, size):
    """The per-axis divisors of the element frame: an ellipsoid's sizes, 1 for a ball, and for the
    elements that are not quadrics (capsule, plane, cube) the closest ellipsoid's: each stretched
    axis reaches as far as the element does, (R + size) / R. Returns (axes, exact)."""
    if kind == "BALL":
        return (1.0, 1.0, 1.0), True
    if kind == "ELLIPSOID":
        return tuple(float(s) for s in size), True
    stretched = _STRETCHED_AXES[kind]
    return tuple((radius + size[i]) / radius if i in stretched else 1.0 for i in range(3)), False


def element_quadric(world_from_element, axes, radius):
    """Q(p) = 1 - |S^-1 W^-1 p|^2 / R^2 as the scene format's 10 coefficients
    A11 A22 A33 A12 A13 A23 A14 A24 A34 A44 (no factor 2 on the cross terms)."""
    inverse = np.linalg.inv(world_from_element)
    scale = 1.0 / (np.asarray(axes, dtype=np.float64) * radius)
    L = scale[:, None] * inverse[:3, :3]   # d / R = L p + l
    l = scale * inverse[:3, 3]
    G = L.T @ L
    b = L.T @ l
    return [-G[0, 0], -G[1, 1], -G[2, 2], -2 * G[0, 1], -2 * G[0, 2], -2 * G[1, 2],
            -2 * b[0], -2 * b[1], -2 * b[2], 1.0 - float(l @ l)]


def element_weight(stiffness, negative):
    """The element's weight: its stiffness as Blender clamps it, negative for a negative element."""
    s = min(float(stiffness), MAX_STIFFNESS)
    return -s if negative else s


def family_name(name):
    """The family of a metaball object: its name without a numeric suffix (".001")."""
    base, dot, number = name.rpartition(".")
    return base if dot and number.isdigit() else name


def family_rank(name):
    """The basis of a family is the member whose suffix is smallest (no suffix: 0)."""
    base, dot, number = name.rpartition(".")
    return int(number) if dot and number.isdigit() else 0


def freeform(threshold, perturbations):
    """The free form: a constant base quadric -threshold, then the elements' quadrics."""
    return {"type": "freeform",
            "base": {"type": "quadric", "coefficients": [0.0] * 9 + [-float(threshold)]},
            "perturbations": perturbations}


def is_finite_quadric(coefficients):
    return all(math.isfinite(c) for c in coefficients)
