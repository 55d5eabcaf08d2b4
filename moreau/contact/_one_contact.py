"""The one-contact closed form of the contact problem, compiled.

The case analysis (:func:`_one_contact`), the tangential-impact test
(:func:`_jam`) and the one-contact residual (:func:`_residual`) that
:mod:`moreau.contact.closed_form` calls. The compiled schemes' contact step
(:mod:`moreau.integrators._contact_step`) calls these same functions, so that
the compiled path and the Python schemes agree bit for bit.
"""

from numba import njit

__all__ = ["_one_contact", "_one_contact_cases", "_jam", "_residual_parts", "_residual"]


@njit(cache=True)
def _one_contact(Wnn, Wnt, Wtn, Wtt, uN, uT, mu, e, vN_pre):
    # returns (pN, pT, ok); ok = False only where W is not positive definite and
    # the problem has no solution or several (see closed_form.one_contact_impulse:
    # with W_NN W_TT > W_NT^2 and the contact pressing, the solution is unique and
    # may be the tangential impact, a stick that the sliding piece cannot give)
    b = uN + e * min(vN_pre, 0.0)
    if b >= 0.0:
        return 0.0, 0.0, True
    if mu > 0.0:
        det = Wnn * Wtt - Wnt * Wtn
        if Wnn - mu * abs(Wnt) > 0.0:
            if det > 0.0:
                pN = (Wnt * uT - Wtt * b) / det
                pT = (Wtn * b - Wnn * uT) / det
                if pN >= 0.0 and abs(pT) <= mu * pN:
                    return pN, pT, True
            pN = -b / (Wnn - mu * Wnt)
            if uT + (Wtn - mu * Wtt) * pN >= 0.0:
                return pN, -mu * pN, True
            pN = -b / (Wnn + mu * Wnt)
            return pN, mu * pN, True
        return _one_contact_cases(Wnn, Wnt, Wtn, Wtt, uT, mu, b, det)
    if not Wnn > 0.0:
        return 0.0, 0.0, False
    return -b / Wnn, 0.0, True


@njit(cache=True)
def _one_contact_cases(Wnn, Wnt, Wtn, Wtt, uT, mu, b, det):
    # _one_contact where Wnn - mu |Wnt| <= 0 (the discrete Painlevé condition fails):
    # every case that holds, which must agree. With b < 0 and det > 0 exactly one
    # holds: along pN the normal velocity falls only on the first slip piece (the
    # paradoxical one, from b < 0, so no root there) and rises on the stick piece
    # after it, whose slope det / Wtt > 0 never ends (a slip piece beyond it would
    # need |Wnt| > mu Wtt, hence Wnn > Wnt^2 / Wtt > mu |Wnt|). Where the free slip
    # runs the paradoxical way the answer is therefore the stick: the tangential
    # impact. A call of its own, so that the common cases are small where a loop
    # inlines them (SPECIALISED)
    nfound = 0
    fN = 0.0
    fT = 0.0
    ok = True
    for case in range(3):
        valid = False
        pN = 0.0
        pT = 0.0
        if case == 0:
            if det != 0.0:
                pN = (Wnt * uT - Wtt * b) / det
                pT = (Wtn * b - Wnn * uT) / det
                valid = pN >= 0.0 and abs(pT) <= mu * pN
        elif case == 1:
            den = Wnn - mu * Wnt
            if den != 0.0:
                pN = -b / den
                pT = -mu * pN
                valid = pN >= 0.0 and uT + (Wtn - mu * Wtt) * pN >= 0.0
        else:
            den = Wnn + mu * Wnt
            if den != 0.0:
                pN = -b / den
                pT = mu * pN
                valid = pN >= 0.0 and uT + (Wtn + mu * Wtt) * pN <= 0.0
        if valid:
            if nfound == 0:
                fN = pN
                fT = pT
            elif (abs(pN - fN) > 1e-9 * (1.0 + abs(fN))
                  or abs(pT - fT) > 1e-9 * (1.0 + abs(fT))):
                ok = False
            nfound += 1
    if nfound == 0:
        ok = False
    return fN, fT, ok


@njit(cache=True)
def _jam(Wnn, Wnt, mu, uN, e, vN_pre, s):
    # a tangential impact: the contact slid the way s (+1: positive slip, -1: negative)
    # in the step before, it presses (b < 0), and its sliding piece that way has a
    # non-increasing normal velocity (W_NN - mu s W_NT <= 0): sliding on has no
    # solution, and the step's answer is the impulsive stick
    b = uN + e * min(vN_pre, 0.0)
    return s != 0.0 and mu > 0.0 and b < 0.0 and Wnn - mu * s * Wnt <= 0.0


@njit(cache=True)
def _residual_parts(Wnn, Wnt, Wtn, Wtt, uN, uT, mu, e, vN_pre, pN, pT):
    # the violation of the one-contact problem's conditions and its scale: the
    # residual is their quotient (_residual)
    b = uN + e * min(vN_pre, 0.0)
    vN = b + Wnn * pN + Wnt * pT
    if not mu > 0.0:
        return abs(min(pN, vN)), 1.0 + abs(b) + abs(Wnn) * abs(pN)
    vT = uT + Wtn * pN + Wtt * pT
    tp = max(pT, 0.0)
    tm = max(-pT, 0.0)
    beta = abs(vT)
    num = max(max(abs(min(pN, vN)), abs(min(tp, vT + beta))),
              max(abs(min(tm, beta - vT)), abs(min(beta, mu * pN - tp - tm))))
    mmax = max(max(abs(Wnn), abs(Wnt)), max(max(abs(Wtn), abs(Wtt)), max(mu, 1.0)))
    scale = 1.0 + max(abs(b), abs(uT)) + mmax * max(max(pN, tp), max(tm, beta))
    return num, scale


@njit(cache=True)
def _residual(Wnn, Wnt, Wtn, Wtt, uN, uT, mu, e, vN_pre, pN, pT):
    num, scale = _residual_parts(Wnn, Wnt, Wtn, Wtt, uN, uT, mu, e, vN_pre, pN, pT)
    return num / scale
