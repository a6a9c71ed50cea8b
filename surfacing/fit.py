"""Fitting the Catmull-Clark limit surface to the curve network (Orbay & Kara 2011, Sec. 4.3.2).

Two solvers over the same inputs: the control points ``P (n, 3)``, the limit
matrix ``L`` (limit points ``L @ P``), the constrained vertices (those sampled on
curves) with their targets, and the control mesh's edges.

* :func:`fit_iterative` -- as published: each iteration moves the curve vertices
  by ``lambda (q_crv - q_limit)`` (Eq. 3, ``lambda = 0.5``) and every other vertex
  by the V-spring displacement computed on the limit surface (Eq. 4).
* :func:`fit_lsq` -- one sparse solve: minimise the control-net fairness
  ``|| F P ||^2`` (umbrella operator; its normal matrix is the discrete
  bi-Laplacian, a thin-plate energy) subject to ``L[c] @ P = q_crv`` exactly
  (the "least squares formulation proposed by [HKD93]" the paper mentions), or
  with a finite ``curve_weight`` as a penalty. The KKT system is factorised once
  with SuperLU (:func:`solve_kkt`) and solved for x, y, z together. With fairness
  *goals* ``g`` it minimises ``|| F P - g ||^2`` instead, one fit per goal from the
  same factorisation: ``g = F @ rest`` on the rows :func:`swept_rows` selects keeps
  the shape of a rest mesh (the swept patches of :mod:`.sweep`) between the curves.

Notes
-----
Fairness rows: smooth vertices use all edge neighbours, crease vertices only their
two neighbours along the crease (so the fairness does not round a crease), corners
none.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from curvenet.core.geometry import face_normals_areas
from curvenet.core.tolerances import DIVISION_GUARD

from .catmull_clark import CORNER, CREASE, edge_topology, sharp_mask, vertex_classes
from .limit import limit_normals

__all__ = ["LAMBDA", "VSPRING_STEP", "FAIRNESS", "PIVOTED_MAX", "QUASI_EPS", "fairness_matrix",
           "variation_matrix", "swept_rows", "fit_lsq", "solve_kkt", "fit_iterative",
           "vspring_displacement", "bending_energy"]

#: Fairness energies of :func:`fit_lsq`: ``"variation"`` penalises the differences of the
#: umbrella Laplacian across edges (``|| D F P ||^2``, a linear stand-in for V-spring's
#: "variation of curvature"); ``"thin-plate"`` penalises the Laplacian (``|| F P ||^2``).
FAIRNESS = ("variation", "thin-plate")
#: Damping factor of Eq. 3 ("In our implementations, we used 0.5 for lambda").
LAMBDA = 0.5
#: Tikhonov pull to the initial control points, relative to the fairness term (keeps
#: the KKT matrix non-singular for vertices the fairness does not reach).
_TIKHONOV = 1e-9
#: KKT systems of :func:`fit_lsq` with at most this many unknowns (control points plus
#: constraints) are factorised with partial pivoting; larger ones as quasi-definite
#: matrices (:func:`solve_kkt`), whose fill grows far slower.
PIVOTED_MAX = 15_000
#: Regularisation of the constraint block of the quasi-definite KKT matrix, relative to
#: the mean diagonal of the fairness block.
QUASI_EPS = 1e-9
#: Iterative refinement of the quasi-definite solve: at most this many steps, until the
#: residual is below this fraction of the right-hand side.
_REFINE_STEPS = 8
_REFINE_RTOL = 1e-13
#: Step applied to the V-spring displacement. The paper applies it whole (1.0); on
#: irregular control meshes from real networks that diverges (haopan/roadster: curve
#: deviation 5% after 50 iterations, 14% after 500), half a step converges.
VSPRING_STEP = 0.5
#: Guard for V-spring's ``1 + n_i . n_j`` when the two normals are opposite.
_VSPRING_DEN_MIN = 1e-2
#: Triangles below this fraction of the median triangle area have no curvature estimate
#: in :func:`bending_energy`.
_DEGENERATE_AREA = 1e-10


def fairness_matrix(quads, n_vertices: int, sharp_edges=None, corners=None) -> sp.csr_matrix:
    """Umbrella operator ``F (n, n)``: ``(F P)_v = P_v - mean of its fairness neighbours``.

    Smooth vertices: all edge neighbours; crease/boundary vertices: the neighbours
    along sharp edges; corners: zero row.
    """
    n = int(n_vertices)
    topo = edge_topology(quads, n)
    sharp = sharp_mask(topo, sharp_edges)
    cls = vertex_classes(topo, sharp, corners)
    e = topo.edges
    both = np.concatenate([e, e[:, ::-1]])
    sh = np.concatenate([sharp, sharp])
    v = both[:, 0]
    keep = (cls[v] == 0) | ((cls[v] == CREASE) & sh)
    keep &= cls[v] != CORNER
    both = both[keep]
    A = sp.coo_matrix((np.ones(len(both)), (both[:, 0], both[:, 1])), shape=(n, n)).tocsr()
    deg = np.asarray(A.sum(axis=1)).ravel()
    has = deg > 0
    inv = np.where(has, 1.0 / np.maximum(deg, 1), 0.0)
    return (sp.diags(has.astype(float)) - sp.diags(inv) @ A).tocsr()


def variation_matrix(F) -> sp.csr_matrix:
    """Edge differences of the umbrella Laplacian: ``(D F) (m, n)``.

    One row per edge ``(i, j)`` whose endpoints are fairness neighbours of each other
    (smooth-smooth, or crease-crease along a crease): ``(F P)_i - (F P)_j``. Its
    energy ``|| D F P ||^2`` is zero on any control net with a constant Laplacian, so
    it bends circles and spheres much less than the thin-plate energy does.
    """
    C = F.tocoo()
    m = C.row != C.col
    r, c = C.row[m], C.col[m]
    n = F.shape[0]
    key = r * n + c
    rev = c * n + r
    mutual = np.isin(rev, key) & (r < c)
    r, c = r[mutual], c[mutual]
    k = np.arange(len(r))
    D = sp.coo_matrix((np.r_[np.ones(len(r)), -np.ones(len(r))], (np.r_[k, k], np.r_[r, c])),
                      shape=(len(r), n)).tocsr()
    return (D @ F).tocsr()


def swept_rows(F, quads, face_patch, swept) -> np.ndarray:
    """Rows of a fairness operator whose every vertex lies on swept patches only.

    Parameters
    ----------
    F : (m, n) sparse
        Fairness operator (:func:`fairness_matrix` or :func:`variation_matrix`).
    quads : (f, 4) int64
    face_patch : (f,) int64
        Patch of each quad.
    swept : (P,) bool
        Patches with a swept rest shape.

    Returns
    -------
    (m,) bool
        True where the row's stencil touches no quad of an unswept patch: there the
        goal ``F @ rest`` of the ``sweep`` fit applies (a curve between two swept
        patches included, so that the rest shape carries across it); elsewhere the
        goal is zero, the plain fairness.
    """
    q = np.asarray(quads, dtype=np.int64)
    n = F.shape[1]
    bad = np.zeros(n, bool)
    bad[q[~np.asarray(swept, bool)[np.asarray(face_patch)]].ravel()] = True
    pattern = F.tocsr().copy()
    pattern.data = np.ones_like(pattern.data)
    return (pattern @ bad.astype(np.float64)) == 0


def fit_lsq(L, F, P0, constrained, targets, *, curve_weight: float | None = None,
            extra=None, goals=None):
    """Direct sparse fit of the limit surface to the curve samples.

    Parameters
    ----------
    L : (n, n) sparse
        Limit-position matrix.
    F : (m, n) sparse
        Fairness operator: :func:`fairness_matrix` (thin plate) or
        :func:`variation_matrix` of it (curvature variation, the default route).
    P0 : (n, 3) float64
        Initial control points (only a 1e-9 Tikhonov anchor).
    constrained : (k,) int64
        Control vertices on curves.
    targets : (k, 3) float64
        Curve samples they must interpolate (limit positions).
    curve_weight : float or None
        None: exact interpolation (KKT). Otherwise the penalty weight of
        ``|| L[c] P - q ||^2`` against the fairness, for the smoothing mode of
        Sec. 4.3.3.
    extra : (A2 (k2, n) sparse, q2 (k2, 3), w2 float), optional
        Soft rows added to the energy as ``w2 || A2 P - q2 ||^2`` (e.g. limit points
        of a finer level along the curves, between the interpolated samples).
    goals : list of (m, 3) float64, optional
        Fairness goals ``g``: minimise ``|| F P - g ||^2`` (None in the list: zero,
        the plain fairness), each a fit of its own from one factorisation.

    Returns
    -------
    P : (n, 3) float64, or (len(goals), n, 3) float64 when ``goals`` is given
    """
    P0 = np.asarray(P0, dtype=np.float64)
    n = len(P0)
    A = L[constrained]
    H = (F.T @ F).tocsr()
    reg = _TIKHONOV * max(H.diagonal().mean(), DIVISION_GUARD)
    H = H + reg * sp.identity(n, format="csr")
    rhs0 = reg * P0
    if extra is not None:
        A2, q2, w2 = extra
        H = (H + w2 * (A2.T @ A2)).tocsr()
        rhs0 = rhs0 + w2 * (A2.T @ np.asarray(q2, dtype=np.float64))
    targets = np.asarray(targets, dtype=np.float64)
    many = goals is not None
    if many:       # one right-hand side of three columns per goal
        rhs0 = np.hstack([rhs0 if g is None else rhs0 + F.T @ np.asarray(g, np.float64)
                          for g in goals])
        targets = np.tile(targets, (1, len(goals)))
    if curve_weight is None:
        P = solve_kkt(H, A, rhs0, targets)[:n]
    elif curve_weight <= 0:
        raise ValueError(f"curve_weight: expected > 0 or None, got {curve_weight}")
    else:
        M = (H + curve_weight * (A.T @ A)).tocsc()
        P = spla.splu(M).solve(rhs0 + curve_weight * (A.T @ targets))
    return P.reshape(n, -1, 3).transpose(1, 0, 2) if many else P


def solve_kkt(H, A, rhs0, targets) -> np.ndarray:
    """Solve ``[[H, A^T], [A, 0]] [P; lam] = [rhs0; targets]``, ``((n + k), c) float64``.

    Parameters
    ----------
    H : (n, n) sparse, symmetric positive definite
    A : (k, n) sparse
    rhs0 : (n, c) float64
    targets : (k, c) float64
        ``c`` right-hand sides (3 per fit: x, y, z).

    Notes
    -----
    Up to :data:`PIVOTED_MAX` unknowns: SuperLU with partial pivoting (column order
    COLAMD), whose fill grows quickly with the mesh (a 16k-vertex control net: 15M
    entries, 2.3 s). Larger systems are factorised as the quasi-definite matrix with
    ``-eps I`` (``eps`` = :data:`QUASI_EPS` times the mean diagonal of ``H``) in place of
    the zero block, in a symmetric minimum-degree order without pivoting, which such a
    matrix allows (Vanderbei 1995): 6M entries, 0.5 s there. Iterative refinement against
    the unregularised matrix then brings the residual to round-off (one or two steps;
    the solution agrees with the pivoted one to 1e-13); should it not, the pivoted
    factorisation is used after all.

    References
    ----------
    R. J. Vanderbei. Symmetric quasi-definite matrices. SIAM J. Optim. 5(1), 1995.
    """
    n, k = H.shape[0], A.shape[0]
    K = sp.bmat([[H, A.T], [A, sp.csr_matrix((k, k))]], format="csc")
    rhs = np.concatenate([rhs0, targets])
    if n + k <= PIVOTED_MAX:
        return spla.splu(K).solve(rhs)
    eps = QUASI_EPS * max(H.diagonal().mean(), DIVISION_GUARD)
    Kq = sp.bmat([[H, A.T], [A, -eps * sp.identity(k, format="csr")]], format="csc")
    lu = spla.splu(Kq, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                   options={"SymmetricMode": True})
    x = lu.solve(rhs)
    tol = _REFINE_RTOL * max(float(np.abs(rhs).max()), DIVISION_GUARD)
    for _ in range(_REFINE_STEPS):
        r = rhs - K @ x
        if np.abs(r).max() <= tol:
            return x
        x = x + lu.solve(r)
    if np.abs(rhs - K @ x).max() <= tol:
        return x
    return spla.splu(K).solve(rhs)


def vspring_displacement(Q, N, edges, smooth=None) -> np.ndarray:
    """V-spring displacement of Eq. 4 at every vertex, from limit points and normals.

    Parameters
    ----------
    Q : (n, 3) float64
        Limit positions.
    N : (n, 3) float64
        Unit limit normals.
    edges : (e, 2) int64
        Control-mesh edges (the one-ring).
    smooth : (n,) bool, optional
        Smooth vertices; a crease or corner neighbour contributes with ``n_i`` in
        place of its own normal (its limit normal averages two sheets).

    Returns
    -------
    (n, 3) float64

    Notes
    -----
    Eq. 4 as printed weighs each neighbour's offset
    ``t_ij = (v_j - v_i).(n_j + n_i) / (1 + n_j.n_i)`` by ``1 / |v_j - v_i|`` and
    divides by the valence, which makes the displacement dimensionless. We normalise
    the same weights instead (``sum w_ij t_ij n_j / sum w_ij``), so the step has
    length units and the result does not depend on the model's scale. The
    Crease neighbours use ``n_j := n_i`` (our addition: the paper has no creases). The
    regularisation term is the tangential part of the umbrella Laplacian,
    ``lap - (lap . n_i) n_i`` (the printed formula drops the trailing ``n_i``).
    """
    e = np.concatenate([edges, edges[:, ::-1]])
    i, j = e[:, 0], e[:, 1]
    d = Q[j] - Q[i]
    ln = np.linalg.norm(d, axis=1)
    w = 1.0 / np.maximum(ln, DIVISION_GUARD)
    Nj = N[j]
    if smooth is not None:
        # across a crease the neighbour's normal belongs to the other sheet: use n_i
        Nj = np.where(smooth[j][:, None], Nj, N[i])
    den = np.maximum(1.0 + np.einsum("ij,ij->i", N[i], Nj), _VSPRING_DEN_MIN)
    t = np.einsum("ij,ij->i", d, N[i] + Nj) / den
    n = len(Q)
    num = np.zeros((n, 3))
    np.add.at(num, i, (w * t)[:, None] * Nj)
    wsum = np.bincount(i, weights=w, minlength=n)
    cnt = np.bincount(i, minlength=n)
    lap = np.zeros((n, 3))
    np.add.at(lap, i, d)
    lap /= np.maximum(cnt, 1)[:, None]
    reg = lap - np.einsum("ij,ij->i", lap, N)[:, None] * N
    return num / np.maximum(wsum, DIVISION_GUARD)[:, None] + reg


def fit_iterative(L, T1, T2, has_tangent, quads, P0, constrained, targets, *,
                  lam: float = LAMBDA, tol: float = 1e-4, max_iter: int = 500,
                  fair_free: bool = True, sharp_edges=None, corners=None,
                  vspring_step: float = VSPRING_STEP):
    """Iterative interpolation with V-spring fairing (Orbay & Kara 2011, Eq. 3-4).

    Parameters
    ----------
    L, T1, T2 : sparse (n, n)
        Limit position and tangent matrices; ``has_tangent (n,) bool``.
    quads : (f, 4) int64
    P0 : (n, 3) float64
    constrained : (k,) int64
    targets : (k, 3) float64
    lam : float
        Damping of Eq. 3 (0.5 in the paper).
    tol : float
        Stop when the largest curve deviation and the largest V-spring step are below
        this (absolute, model units).
    max_iter : int
    fair_free : bool
        Apply V-spring to the free (not on a curve) vertices.
    sharp_edges, corners : optional
        Crease structure (see :mod:`.catmull_clark`), for the V-spring neighbours.
    vspring_step : float
        Fraction of the Eq. 4 displacement applied per iteration (1.0 as published;
        default :data:`VSPRING_STEP`).

    Returns
    -------
    P : (n, 3) float64
    iterations : int
    max_deviation : float
        ``max |q_crv - L[c] P|`` at exit.
    """
    if not 0.0 < lam <= 1.0:
        raise ValueError(f"lam: expected in (0, 1], got {lam}")
    P = np.asarray(P0, dtype=np.float64).copy()
    n = len(P)
    free = np.ones(n, bool)
    free[constrained] = False
    topo = edge_topology(quads, n)
    edges = topo.edges
    cls = vertex_classes(topo, sharp_mask(topo, sharp_edges), corners)
    smooth = cls == 0
    iterations = 0
    for iterations in range(1, max_iter + 1):  # noqa: B007 (reported after the loop)
        Q = L @ P
        res = targets - Q[constrained]
        dev = float(np.sqrt((res ** 2).sum(1)).max()) if len(res) else 0.0
        P[constrained] += lam * res                                  # Eq. 3
        step = 0.0
        if fair_free and free.any():
            N = limit_normals(P, quads, T1, T2, has_tangent, L)
            dv = vspring_step * vspring_displacement(Q, N, edges, smooth)[free]   # Eq. 4
            P[free] += dv
            step = float(np.sqrt((dv ** 2).sum(1)).max())
        if dev < tol and step < tol:
            break
    Q = L @ P
    res = targets - Q[constrained]
    dev = float(np.sqrt((res ** 2).sum(1)).max()) if len(res) else 0.0
    return P, iterations, dev


def bending_energy(vertices, faces) -> float:
    """Discrete Willmore energy ``sum_v |H_v|^2 A_v`` of a triangle mesh, open-boundary
    vertices left out.

    ``H_v`` is the mean curvature from the cotangent Laplacian (``|L x| / 2 A_v``),
    ``A_v`` the vertex's Voronoi area (libigl). Scale invariant: a round sphere of any
    size gives ``4 pi``, and folds, flattened caps and bulges between curves raise it.
    Triangles of (nearly) zero area, which limit meshes of control nets with coincident
    points have, have no cotangents: they are left out, and their vertices with them
    (their one-rings are open).

    Parameters
    ----------
    vertices : (n, 3) float64
    faces : (f, 3) int64

    Returns
    -------
    float
    """
    import igl

    V = np.ascontiguousarray(vertices, dtype=np.float64)
    F = np.ascontiguousarray(faces, dtype=np.int64)
    _, face_area = face_normals_areas(V, F)
    F = np.ascontiguousarray(F[face_area > _DEGENERATE_AREA * max(float(np.median(face_area)),
                                                                  DIVISION_GUARD)])
    if not len(F):
        return 0.0
    L = igl.cotmatrix(V, F)
    area = np.zeros(len(V))                # libigl sizes it by the largest index used
    mass = igl.massmatrix(V, F, igl.MASSMATRIX_TYPE_VORONOI).diagonal()
    area[:len(mass)] = mass
    hn = (L @ V) / (2.0 * np.maximum(area, DIVISION_GUARD)[:, None])
    e = np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1)
    _, idx, count = np.unique(e, axis=0, return_index=True, return_counts=True)
    inner = np.zeros(len(V), bool)
    inner[F.ravel()] = True
    inner[e[idx[count == 1]].ravel()] = False          # open-boundary vertices
    return float(((hn ** 2).sum(1) * area)[inner].sum())
