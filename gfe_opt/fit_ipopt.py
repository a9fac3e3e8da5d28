"""The old minimiser of effect fits (``GFE_OPT_FIT_SOLVER=ipopt``, kept for comparison in
``scripts/bench.py``): IPOPT through CasADi callbacks finds the valley, then
:func:`gfe_opt.fitting._finish` converges.  Imported only when chosen, so that fits and the
command line do not load CasADi."""

from __future__ import annotations

import casadi as ca
import numpy as np

#: IPOPT runs restarted from where the last ended while each lowers χ² by more than this
RESTART_GAIN = 0.9
MAX_RESTARTS = 4


def ipopt_valley(residual, chi2, z_start, lower, upper, max_iter):
    """IPOPT on ½‖r‖²/scale from ``z_start``, restarted from where it ended while χ² keeps
    falling by more than 10 % (the objective is scaled by χ² at the start, so a run that
    lowers χ² a hundredfold meets its tolerances early).  Never worse than the start.
    Returns (z, χ², the last run's status)."""
    z, value = z_start, chi2(z_start)
    status = "Nothing_To_Fit"
    n = z.size
    for _ in range(MAX_RESTARTS):
        scale = max(value, 1.0)  # objective starts at 1/2: relative tolerances
        objective = _GaussNewton(residual, n, scale, lower, upper)
        x = ca.MX.sym("z", n)
        solver = ca.nlpsol("effects", "ipopt", {"x": x, "f": objective(x)},
                           {"ipopt.print_level": 0, "print_time": False, "ipopt.sb": "yes",
                            "ipopt.max_iter": max_iter, "ipopt.tol": 1e-3,
                            # measured: the adaptive barrier halves the evaluations
                            "ipopt.mu_strategy": "adaptive",
                            # on a flat objective with finite-difference gradients the line
                            # search backtracked 20-40 times a step: accept after 4
                            "ipopt.accept_after_max_steps": 4,
                            # no "acceptable" stop: the finish converges (see above)
                            "ipopt.acceptable_iter": 0})
        sol = solver(x0=z, lbx=lower, ubx=upper)
        stats = solver.stats()
        trial = np.array(sol["x"]).ravel()
        trial_value = chi2(trial)
        status = str(stats.get("return_status"))
        if not trial_value < value:  # never return worse than the start (nor NaN)
            break
        gain = trial_value < RESTART_GAIN * value
        z, value = trial, trial_value
        if not gain:
            break
    return z, value, status


# -------------------------------------------------------------------------------------------
# CasADi callbacks: ½‖r‖², its gradient Jᵀr and the Gauss–Newton Hessian JᵀJ
# -------------------------------------------------------------------------------------------


class _GaussNewton(ca.Callback):
    """½‖r(z)‖² as a CasADi function of z with its gradient Jᵀr and the Gauss–Newton
    Hessian JᵀJ, J the forward-difference Jacobian of r, computed once per point and shared:
    IPOPT sees only n × n matrices, however many residuals there are."""

    def __init__(self, residual, n: int, scale: float, lower, upper, step: float = 1e-6):
        ca.Callback.__init__(self)
        self.residual, self.n, self.step = residual, n, step
        self.root = np.sqrt(scale)
        self.lower, self.upper = lower, upper
        self._point = None
        self.construct("half_sum_of_squares", {})

    def fun(self, z):
        return self.residual(z) / self.root

    def residual_and_jacobian(self, z):
        key = z.tobytes()
        if self._point is None or self._point[0] != key:
            r0 = self.fun(z)
            analytic = getattr(self.residual, "jacobian", None)
            inside = np.clip(z, self.lower, self.upper)
            jac = None   # IPOPT may step a hair outside the bounds: differences there
            if analytic is not None and np.array_equal(inside, z):
                jac = analytic(inside, r0, self.lower, self.upper)   # (None: condensed)
            jac = self._forward(z, r0) if jac is None else jac / self.root
            self._point = (key, r0, jac)
        return self._point[1], self._point[2]

    def _forward(self, z, r0):
        jac = np.zeros((r0.size, self.n))
        for k in range(self.n):
            dz = z.copy()
            h = self.step * max(1.0, abs(z[k]))
            dz[k] += h
            jac[:, k] = (self.fun(dz) - r0) / h
        return jac

    def get_n_in(self):
        return 1

    def get_n_out(self):
        return 1

    def get_sparsity_in(self, i):
        return ca.Sparsity.dense(self.n, 1)

    def get_sparsity_out(self, i):
        return ca.Sparsity.dense(1, 1)

    def eval(self, arg):
        r = self.fun(np.array(arg[0]).ravel())
        return [0.5 * float(r @ r)]

    def has_jacobian(self):
        return True

    def get_jacobian(self, name, inames, onames, opts):
        self._gradient = _Gradient(name, self)
        return self._gradient


class _Gradient(ca.Callback):
    """d(½‖r‖²)/dz = (Jᵀr)ᵀ; its own Jacobian is the Gauss–Newton Hessian."""

    def __init__(self, name, outer: _GaussNewton):
        ca.Callback.__init__(self)
        self.outer = outer
        self.construct(name, {})

    def get_n_in(self):
        return 2

    def get_n_out(self):
        return 1

    def get_sparsity_in(self, i):
        return ca.Sparsity.dense(self.outer.n, 1) if i == 0 else ca.Sparsity.dense(1, 1)

    def get_sparsity_out(self, i):
        return ca.Sparsity.dense(1, self.outer.n)

    def eval(self, arg):
        r, jac = self.outer.residual_and_jacobian(np.array(arg[0]).ravel())
        return [(jac.T @ r)[None, :]]

    def has_jacobian(self):
        return True

    def get_jacobian(self, name, inames, onames, opts):
        self._hessian = _Hessian(name, self.outer)
        return self._hessian


class _Hessian(ca.Callback):
    """JᵀJ (the second derivative of r neglected) and a zero derivative with respect to
    the objective value."""

    def __init__(self, name, outer: _GaussNewton):
        ca.Callback.__init__(self)
        self.outer = outer
        self.construct(name, {})

    def get_n_in(self):
        return 3

    def get_n_out(self):
        return 2

    def get_sparsity_in(self, i):
        n = self.outer.n
        return [ca.Sparsity.dense(n, 1), ca.Sparsity.dense(1, 1), ca.Sparsity.dense(1, n)][i]

    def get_sparsity_out(self, i):
        return ca.Sparsity.dense(self.outer.n, self.outer.n) if i == 0 else \
            ca.Sparsity.dense(self.outer.n, 1)

    def eval(self, arg):
        _, jac = self.outer.residual_and_jacobian(np.array(arg[0]).ravel())
        return [jac.T @ jac, np.zeros((self.outer.n, 1))]
