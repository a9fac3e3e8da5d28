"""Generic families derived from constraints reproduce the paper's eqs. 2, 11, 16 and 17."""

import numpy as np
import sympy

from gfe_opt import elements as el
from gfe_opt.derive import generic_family, generic_family_symbolic

SWAP = np.array([[0.0, 1.0], [1.0, 0.0]])
CENTRE_MODES = np.array([[1.0, 0, 1, 0], [-0.5, 1, 0.5, 1]]).T  # translation, centre rotation


def _same_family(family, constant, basis):
    assert family.n_params == len(basis)
    assert family.contains(constant)
    for b in basis:
        assert family.contains(constant + b)


def test_bar_eq2():
    stiff = generic_family(2, null_space=el.BAR_RIGID_MODES)
    _same_family(stiff, np.zeros((2, 2)), [el.BAR_STIFFNESS_BASIS["k"]])
    mass = generic_family(2, rigid_modes=el.BAR_RIGID_MODES, rigid_mass=[[1.0]], symmetry=SWAP)
    _same_family(mass, el.BAR_MASS_CONSTANT, [el.BAR_MASS_BASIS["beta"]])


def test_beam_eq11_and_eq16():
    _same_family(generic_family(4, null_space=el.BEAM_RIGID_MODES), np.zeros((4, 4)),
                 list(el.BEAM_STIFFNESS_BASIS.values()))
    sym = generic_family(4, null_space=el.BEAM_RIGID_MODES, symmetry=el.BEAM_SYMMETRY_R)
    _same_family(sym, np.zeros((4, 4)), list(el.SYMMETRIC_BEAM_STIFFNESS_BASIS.values()))
    # the general eq. 11 element is not symmetric: it is outside the eq. 16 family
    assert not sym.contains(el.BEAM_STIFFNESS_BASIS["k_ww"])


def test_beam_mass_eq17_with_total_mass_and_inertia():
    fam = generic_family(4, rigid_modes=CENTRE_MODES, rigid_mass=np.diag([1.0, 1.0 / 12.0]),
                         symmetry=el.BEAM_SYMMETRY_R)
    _same_family(fam, el.SYMMETRIC_BEAM_MASS_CONSTANT,
                 list(el.SYMMETRIC_BEAM_MASS_BASIS.values()))
    # a different inertia moves the family off eq. 17's m24 relation
    other = generic_family(4, rigid_modes=CENTRE_MODES, rigid_mass=np.diag([1.0, 0.2]),
                           symmetry=el.BEAM_SYMMETRY_R)
    assert not other.contains(el.symmetric_beam_mass(**el.CONSISTENT_BEAM_MASS))


def test_symbolic_families_match_the_paper():
    X, free = generic_family_symbolic(4, null_space=el.BEAM_RIGID_MODES.astype(int).tolist(),
                                      symmetry=el.BEAM_SYMMETRY_R.astype(int).tolist())
    assert len(free) == 2
    values = dict(zip(free, (sympy.Rational(3, 7), sympy.Rational(-5, 2))))
    Xn = np.array(X.subs(values).tolist(), dtype=float)
    assert np.allclose(Xn, el.symmetric_beam_stiffness(Xn[0, 0], Xn[1, 1]))

    half = sympy.Rational(1, 2)
    phi = [[1, -half], [0, 1], [1, half], [0, 1]]
    M, free = generic_family_symbolic(4, rigid_modes=phi,
                                      rigid_mass=[[1, 0], [0, sympy.Rational(1, 12)]],
                                      symmetry=el.BEAM_SYMMETRY_R.astype(int).tolist())
    assert len(free) == 4
    # m24 = 1/6 - m11/2 + m12 + m14 - m22 holds identically
    m24 = sympy.Rational(1, 6) - M[0, 0] / 2 + M[0, 1] + M[0, 3] - M[1, 1]
    assert sympy.simplify(M[1, 3] - m24) == 0
    assert sympy.simplify(M[0, 2] - (half - M[0, 0])) == 0


def test_inconsistent_constraints_are_reported():
    import pytest

    with pytest.raises(ValueError, match="inconsistent"):
        generic_family(2, null_space=el.BAR_RIGID_MODES, rigid_modes=el.BAR_RIGID_MODES,
                       rigid_mass=[[1.0]])
