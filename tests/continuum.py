"""A 2-D plane-stress continuum beam with real geometry (scikit-fem), for truths outside
the package's beam family (issue 21).

A rectangle L × h (breadth b out of plane) meshed with quadratic quadrilaterals; a notch is
cut out of the mesh (double-edged: both faces, each cut ``depth_ratio`` of the half depth,
``width`` wide), a thinned zone or a welded doubler changes the local thickness, a block
adds mass.  Supports are held as a test holds them: ``"pin"`` fixes the point at mid-height
of an end (both directions; the other end's mid-height point only vertically when both
are pins), ``"clamp"`` the whole end face, ``"free"`` nothing.  Sensors read the vertical
displacement on the mid-height line.  Bending modes are told from axial ones by their
vertical motion there.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse.linalg as spla
from skfem import Basis, BilinearForm, ElementQuad2, ElementVector, MeshQuad, asm
from skfem.helpers import dot
from skfem.models.elasticity import linear_elasticity


def _grid(length, nx, refine_at=(), refine_width=0.0):
    """x grid with extra lines at and around ``refine_at`` (notch faces)."""
    x = list(np.linspace(0.0, length, nx + 1))
    for xc in refine_at:
        for k in (-1.0, -0.5, -0.25, 0.0, 0.25, 0.5, 1.0):
            x.append(xc + k * refine_width)
    x = np.unique(np.clip(np.round(np.array(x), 12), 0.0, length))
    return x


def continuum_modes(length, depth, breadth, E, nu, rho, *, n_modes, sensors,
                    supports=("pin", "pin"), notch=None, thickness=None, nx=None, ny=8,
                    point_mass=None, supports_at=()):
    """(frequencies [Hz], vertical midline shapes (sensors, modes)) of the first
    ``n_modes`` bending modes.

    notch: (x_c, width, depth_ratio) double-edged; thickness: callable t(x)/breadth of the
    out-of-plane thickness (a thinned zone < 1, a doubler > 1; stiffness and mass both);
    point_mass: (x, kg) lumped on the mid-height point (an attached block);
    supports_at: x positions of extra vertical point supports at mid-height (a roller).
    """
    nx = nx or int(round(6 * length / depth * ny / 8)) * 2
    faces = []
    if notch is not None:
        xc, width, a = notch
        faces = [xc - width / 2, xc + width / 2]
    xs = _grid(length, nx, faces, (notch[1] if notch else 0.0))
    if notch is not None:
        cut = a * depth / 2
        ys = np.unique(np.concatenate([np.linspace(-depth / 2, depth / 2, ny + 1),
                                       [-depth / 2 + cut, depth / 2 - cut]]))
    else:
        ys = np.linspace(-depth / 2, depth / 2, ny + 1)
    ys = np.unique(np.concatenate([ys, [0.0]]))
    mesh = MeshQuad.init_tensor(xs, ys)
    if notch is not None:
        mid = mesh.p[:, mesh.t].mean(axis=1)
        out = np.flatnonzero((np.abs(mid[0] - xc) < width / 2)
                             & (np.abs(mid[1]) > depth / 2 - cut))
        mesh = mesh.remove_elements(out)
    element = ElementVector(ElementQuad2())
    basis = Basis(mesh, element, intorder=4)
    lam_ps = E * nu / (1 - nu**2)            # plane-stress Lamé λ*
    mu = E / (2 * (1 + nu))
    t = thickness or (lambda x: np.ones_like(x))

    @BilinearForm
    def mass(u, v, w):
        return rho * breadth * t(w.x[0]) * dot(u, v)

    stiff = linear_elasticity(lam_ps, mu)

    @BilinearForm
    def stiffness(u, v, w):
        return breadth * t(w.x[0]) * stiff.form(u, v, w)

    K = asm(stiffness, basis)
    M = asm(mass, basis)
    nodal = basis.nodal_dofs  # (2, n_nodes): x and y dofs of the vertices
    p = mesh.p

    def at(x, y):
        return int(np.argmin((p[0] - x) ** 2 + (p[1] - y) ** 2))

    fixed = []
    for side, kind in zip((0.0, length), supports):
        if kind == "pin":
            node = at(side, 0.0)
            fixed += [nodal[1, node]] + ([nodal[0, node]] if side == 0.0 or
                                        supports[0] != "pin" else [])
        elif kind == "clamp":
            edge = basis.get_dofs(lambda q, s=side: np.isclose(q[0], s))
            fixed += list(edge.all())
    for xs_ in supports_at:
        fixed.append(nodal[1, at(xs_, 0.0)])
    if point_mass is not None:
        node = at(point_mass[0], 0.0)
        M = M.tolil()
        for d in (nodal[0, node], nodal[1, node]):
            M[d, d] += point_mass[1]
        M = M.tocsr()
    fixed = np.unique(np.array(fixed, dtype=int))
    free = np.setdiff1d(np.arange(K.shape[0]), fixed)
    Kf, Mf = K[free][:, free].tocsc(), M[free][:, free].tocsc()
    rigid = 3 if supports == ("free", "free") else 0
    want = 3 * n_modes + rigid + 4   # axial modes interleave: ask for more
    shift = -(2 * np.pi * 1.0) ** 2
    lam, vec = spla.eigsh(Kf, k=min(want, Kf.shape[0] - 2), M=Mf, sigma=shift, which="LM",
                          v0=np.ones(Kf.shape[0]))
    order = np.argsort(lam)
    lam, vec = lam[order], vec[:, order]
    full = np.zeros((K.shape[0], vec.shape[1]))
    full[free] = vec
    line = np.array([np.asarray(sensors, float), np.zeros(len(sensors))])
    mid = np.array([np.linspace(0, length, 101), np.zeros(101)])
    vx, vy = _components(basis, mid, full)   # bending modes move the mid-height line vertically
    keep = [j for j in range(full.shape[1])
            if not (rigid and lam[j] < 1e-6 * max(abs(lam).max(), 1.0))
            and np.max(np.abs(vy[:, j])) > np.max(np.abs(vx[:, j]))][:n_modes]
    if len(keep) < n_modes:
        raise RuntimeError("not enough bending modes found")
    f = np.sqrt(np.maximum(lam[keep], 0.0)) / (2 * np.pi)
    return f, _components(basis, line, full[:, keep])[1]


def _components(basis, points, vectors):
    """x and y displacements of ``vectors`` (global dofs) at ``points`` (2, n): scikit-fem's
    probes of a vector element stack the components, [x at every point, y at every point]."""
    values = basis.probes(points) @ vectors
    n = points.shape[1]
    return values[:n], values[n:]
