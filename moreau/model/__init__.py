"""The model layer, on the ground floor: what a mechanical system is, below every scheme and analysis.

:mod:`moreau.model.scene`
    the scene interface (:class:`Scene`) an integrator runs;
:mod:`moreau.model.registry`
    the scene registry: scenes register themselves, schemes and analyses
    look them up by name, studies register their hooks;
:mod:`moreau.model.units`
    unit conversions shared by the scenes (the drive scaling, SI scales).

The compiled form of a scene's model, :class:`moreau.compiled.CompiledModel`,
is on this floor too. Nothing here imports a scheme, an analysis or a scene:
the scenes live above, in :mod:`moreau.scenes`, and register themselves here.
"""

from . import registry
from .registry import Parameter, SceneEntry, get_entry, make_scene, register_scene, scene_names
from .scene import Scene, params_with

__all__ = ["Scene", "params_with", "registry", "Parameter", "SceneEntry", "get_entry",
           "make_scene", "register_scene", "scene_names"]
