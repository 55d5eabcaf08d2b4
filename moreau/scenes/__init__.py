"""Mechanical systems ("scenes") that the integrators run."""

from .base import Scene
