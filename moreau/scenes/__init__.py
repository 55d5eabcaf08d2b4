"""Mechanical systems ("scenes") that the integrators run.

Each scene lives in its own module and registers itself there
(:mod:`moreau.model.registry`); nothing here lists them. The scene classes
and their public names are reachable as attributes of this package
(``from moreau.scenes import BouncingBall``): the first such lookup imports
every scene module (:func:`moreau.model.registry.discover`).
"""

import importlib

from ..model import registry
from ..model.scene import Scene, params_with
from ..model.registry import get_entry, make_scene, register_scene, scene_names

__all__ = ["Scene", "params_with", "registry", "get_entry", "make_scene", "register_scene",
           "scene_names"]


def __getattr__(name):
    # PEP 562: the public names of the scene modules, found after discovery
    # a submodule not yet imported is looked up here first by ``from moreau.scenes
    # import x``; it must fall through to the import system, not start discovery
    if name.startswith("_") or f"{__name__}.{name}" in registry.scene_modules():
        raise AttributeError(name)
    registry.discover()
    for module in registry.scene_modules():
        mod = importlib.import_module(module)
        if name in getattr(mod, "__all__", ()):
            value = getattr(mod, name)
            globals()[name] = value
            return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
