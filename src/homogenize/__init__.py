"""Micromechanical effective stress (thesis Eqs. 3.41-3.57) and regular packings (Chapter 4)."""

from .contact_stress import contact_stress
from .fabric import fabric_anisotropy, fabric_tensor

__all__ = ["contact_stress", "fabric_anisotropy", "fabric_tensor"]
