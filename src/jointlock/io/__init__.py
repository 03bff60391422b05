"""Readers of model files: URDF and jointlock's TOML model format."""

from .modelfile import read_model_toml
from .urdf import read_urdf

__all__ = ["read_model_toml", "read_urdf"]
