"""The contact problem of one time step, as the time-stepping schemes call it.

Its content moved to :mod:`moreau.contact.closed_form`; the names stay here for the schemes.
"""

from ..contact import closed_form as _cf
from ..contact.closed_form import (MAX_PIECES_CONTACTS, PAINLEVE_POLICIES, check_painleve,  # noqa: F401
                                   friction_pieces, new_contact_counters, one_contact_impulse,
                                   one_contact_residual, painleve_option, sliding_regimes,
                                   slip_signs, solve_contact_problem, tangential_impact)

__all__ = _cf.__all__ + ["MAX_PIECES_CONTACTS", "friction_pieces"]
