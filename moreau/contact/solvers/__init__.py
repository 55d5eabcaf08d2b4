"""The contact-problem solvers, one module each; importing a module registers its solver.

Every public module of this folder is imported with :mod:`moreau.contact`, so
that a new solver is one new file calling
:func:`moreau.contact.register_solver` at import.

=============== =============================================================
``closed-form`` one contact, exact case analysis (:mod:`.closed_form`)
``lemke``       the dense friction LCP by Lemke's method (:mod:`.lemke`)
``qp``          the friction LCP by the QP (Tresca fixed point) method (:mod:`.qp`)
``auto``        closed form for one contact, Lemke then QP up to 32 contacts,
                NSGS above; ``mlcp`` where there are equality rows (:mod:`.auto`)
``mlcp``        equality rows eliminated (Schur complement), then an inner
                solver on the contacts (:mod:`.mlcp`)
``nsgs``        nonsmooth Gauss-Seidel in FCLib's layout, ``W`` in CSR (:mod:`.nsgs`)
``apgd``        accelerated projected gradient in FCLib's layout (:mod:`.apgd`)
=============== =============================================================
"""

import importlib
import pkgutil

for _module in pkgutil.iter_modules(__path__):
    if not _module.name.startswith("_"):
        importlib.import_module(f"{__name__}.{_module.name}")
