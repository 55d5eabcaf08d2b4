"""Operation-mode names; moved to :mod:`moreau.modes` (kept here as an alias).

The naming is used by the scene references in ``integrators/`` as well as by
the analyses, so it lives below both layers now.
"""

from ..modes import impacts_after_flight, mode_name, split_tokens, step_letters  # noqa: F401

__all__ = ["mode_name", "split_tokens", "step_letters", "impacts_after_flight"]
