"""Zero-energy motions: the null vectors of a tangent, told by what they are.

A fibre that nothing holds in some direction has a singular tangent K: its
sections free to spin about its axis (supports or junctions on the centre
line only), a fibre free to slide along itself between frictionless
contacts, a fibre with no support at all. In exact arithmetic the motion
has a zero eigenvalue; in the LDL^T factorization it gives a round-off
pivot of either sign, which the inertia may count as a negative eigenvalue.

The size of an eigenvalue cannot tell such a pivot from a genuine loss of
stability: the softest bending stiffness of a fibre is of the order of
(R/L)^2 / N^2 of its axial stiffness (N elements; 1e-11 at L/R = 10^4 with
32 elements), an eigenvalue just past a bifurcation is a fraction of that,
and a threshold on it depends on the units and the slenderness (the one
used before called a column's buckling at L/R = 2000 a zero mode). A
zero-energy motion is therefore recognized by its shape first, by its
energy second:

1. **Candidates** (``fibre_generators``). Per fibre, at the current
   configuration, the motions that strain nothing: three translations, the
   rotations about the two axes across the fibre's principal direction
   (positions and section vectors turn together) and the spin of its
   sections about their normals g1 x g2 (positions in place). For a
   straight fibre these are its six rigid motions. For a bent one the spin
   takes the place of the rotation about the principal direction: it is
   the one that stays (nearly) strain-free, and the two together would
   span a bending of the fibre, whose energy may be as small as a slender
   fibre's genuine negative eigenvalue. Only the combinations that move no
   constrained unknown are admissible: a clamped fibre has none, a fibre
   pinned at one end keeps its rotations about the pin and its spin.
2. **Energy.** A fibre's own elasticity does not resist its candidates;
   something else may (contact, junctions, the loads: a lateral load on a
   fibre pinned at both ends resists its turn about the pins). With D the
   row sums of |K| and the candidates orthonormal in the metric D (a
   scaling that makes the test independent of each unknown's unit:
   positions are lengths, section vectors are dimensionless), the Ritz
   values of K on a fibre's candidates are energies relative to the round-
   off scale of y^T K y (|y|^T |K| |y| <= y^T D y = 1). A Ritz vector
   whose energy is within ZERO_MOTION_TOLERANCE of zero, and which pulls on
   no constraint row (a rigid-body multiplier, where the energy is blind),
   is a zero-energy motion.

What is not covered: a joint rigid motion of several fibres that hold
each other but nothing holds as a group; motions of the other fields (a
free rigid body, an unsupported matrix block); a bent fibre free to turn
rigidly about its principal direction (a buckled column between two pins
and no other load: a mechanism). Their round-off pivots are counted as
negative eigenvalues: a false alarm, never a missed instability.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse
from mpi4py import MPI
from petsc4py import PETSc

from .. import _cpp
from ..solver.convergence import EPS

#: A Ritz vector of a fibre's candidates is a zero-energy motion when its
#: energy (module docstring: relative to the round-off scale of y^T K y)
#: is at most this. Measured (tests/stability/test_zero_motions.py): the
#: free spin of a straight fibre, L/R 10 to 10^4, E 1 and 1e9: 0.0007 to
#: 1.14 eps; a held candidate, the spin of a fibre bent along an arc of
#: 1.5 rad, at every node's position held: 1.3e7 eps at L/R = 10^4 (1.5e12
#: at 10). 1e3 eps sits between, a factor 900 above the spins' round-off;
#: a resistance below it is zero to working precision.
ZERO_MOTION_TOLERANCE = 1e3 * EPS


@dataclass
class ZeroMotion:
    """One zero-energy motion: the fibre it moves, what it is ("spin": the
    sections turn about the fibre's axis; "rigid": the fibre moves as a
    rigid body), its vector (global layout, unit norm) and its energy
    y^T K y in the scaled metric (module docstring)."""

    fibre: int
    kind: str
    vector: PETSc.Vec
    energy: float


def fibre_generators(q: np.ndarray) -> np.ndarray:
    """The 6 motions that (nearly) strain nothing of a fibre with nodal
    unknowns q (n, 9) = [x, g1, g2]: (9 n, 6) = 3 translations, the
    rotations about the 2 axes across its principal direction (through the
    centroid; positions and section vectors turn together) and the spin of
    its sections about their normals g1 x g2 (positions in place). For a
    straight fibre these are its rigid motions. For a bent one the spin
    stands for the rotation about the principal direction: the two differ
    by a bending of the fibre, which must not be a candidate."""
    x, g1, g2 = q[:, 0:3], q[:, 3:6], q[:, 6:9]
    n = len(q)
    centred = x - x.mean(axis=0)
    axes = np.linalg.svd(centred, full_matrices=True)[2] if n > 1 else np.eye(3)
    out = np.zeros((n, 9, 6))
    for k in range(3):
        out[:, k, k] = 1.0
    for k, e in enumerate(axes[1:3]):
        e = np.broadcast_to(e, (n, 3))
        out[:, 0:3, 3 + k] = np.cross(e, centred)
        out[:, 3:6, 3 + k] = np.cross(e, g1)
        out[:, 6:9, 3 + k] = np.cross(e, g2)
    normal = np.cross(g1, g2)
    normal /= np.linalg.norm(normal, axis=1)[:, None]
    out[:, 3:6, 5] = np.cross(normal, g1)
    out[:, 6:9, 5] = np.cross(normal, g2)
    return out.reshape(9 * n, 6)


def _span(a: np.ndarray) -> np.ndarray:
    """Orthonormal basis of the columns of a (numerical rank: numpy's
    default, max(shape) eps times the largest singular value)."""
    if a.shape[1] == 0:
        return a
    u, s, _ = np.linalg.svd(a, full_matrices=False)
    tol = max(a.shape) * EPS * (s[0] if len(s) else 0.0)
    return u[:, s > tol]


def _null_space(a: np.ndarray) -> np.ndarray:
    """Orthonormal basis of the null space of a (numpy's default rank)."""
    if a.shape[0] == 0:
        return np.eye(a.shape[1])
    _, s, vt = np.linalg.svd(a)
    tol = max(a.shape) * EPS * (s[0] if len(s) else 0.0)
    rank = int(np.sum(s > tol))
    return vt[rank:].T


def admissible_motions(model, row_scale: np.ndarray) -> list[tuple[int, np.ndarray]]:
    """Per fibre, a basis of its strain-free motions that move no
    constrained unknown, orthonormal in the scaled metric (columns of
    row_scale^1/2 * basis orthonormal); ``row_scale``: (nodes, 9) positive
    weights of every beam unknown (all ranks). Collective."""
    mesh = model.mesh
    q = model.nodal_unknowns()
    constrained = model.beam_global_dofs() < 0
    out = []
    for f in range(len(mesh.fibres)):
        lo, hi = mesh.first_node[f], mesh.first_node[f + 1]
        g = fibre_generators(q[lo:hi])
        g /= np.linalg.norm(g, axis=0)  # unit columns: rank decisions independent of units
        c = constrained[9 * lo:9 * hi]
        keep = _null_space(g[c])
        if keep.shape[1] == 0:
            continue
        root = np.sqrt(row_scale[lo:hi].ravel())
        scaled = root[:, None] * (g @ keep)
        scaled[c] = 0.0
        basis = _span(scaled)
        if basis.shape[1]:
            out.append((f, basis / root[:, None]))
    return out


def _motion_matrix(model, K: PETSc.Mat, motions) -> tuple[PETSc.Mat, np.ndarray]:
    """The admissible motions as the columns of a sparse matrix (rows: the
    global system, this rank's owned beam rows), and each fibre's first
    column."""
    mesh = model.mesh
    all_dofs = model.beam_global_dofs(constrained=True)
    rstart, rend = K.getOwnershipRange()
    starts = np.cumsum([0] + [b.shape[1] for _, b in motions])
    rows, cols, vals = [], [], []
    for (f, basis), c0 in zip(motions, starts):
        n0, n1 = mesh.first_node[f], mesh.first_node[f + 1]
        nodes = np.arange(n0, n1)[mesh.owns(np.arange(n0, n1))]
        if len(nodes) == 0:
            continue
        unrolled = (9 * nodes[:, None] + np.arange(9)).ravel()
        block = basis[unrolled - 9 * n0]
        r = all_dofs[unrolled] - rstart
        rows.append(np.repeat(r, block.shape[1]))
        cols.append(np.tile(np.arange(c0, c0 + block.shape[1]), len(r)))
        vals.append(block.ravel())
    m = rend - rstart
    rows = np.concatenate(rows) if rows else np.zeros(0, dtype=np.int64)
    cols = np.concatenate(cols) if cols else np.zeros(0, dtype=np.int64)
    vals = np.concatenate(vals) if vals else np.zeros(0)
    local = scipy.sparse.csr_matrix((vals, (rows, cols)), shape=(m, int(starts[-1])))
    local.sort_indices()
    Q = PETSc.Mat().createAIJ(size=((m, K.getSize()[0]), (PETSc.DECIDE, int(starts[-1]))),
                              csr=(local.indptr.astype(PETSc.IntType),
                                   local.indices.astype(PETSc.IntType), local.data),
                              comm=K.getComm())
    Q.assemble()
    return Q, starts


class _Candidates:
    """Each fibre's admissible candidates (the columns of Q, orthonormal in
    the scaled metric) and their Ritz matrices Q_f^T K Q_f. Collective."""

    def __init__(self, model, K: PETSc.Mat):
        ones = K.createVecRight()
        ones.set(1.0)
        row_sums = K.createVecLeft()
        _cpp.absolute_product(K, ones, row_sums)
        # every row of |K| sums to > 0 (constrained rows are unit rows);
        # guard the scaling all the same
        sums = row_sums.getArray(readonly=True)
        self.sums = np.where(sums > 0, sums, 1.0)
        row_sums.setArray(self.sums)
        self.motions = admissible_motions(model, model.beam_values(row_sums))
        ones.destroy()
        row_sums.destroy()
        self.ritz = []
        if not self.motions:
            return
        self.Q, self.starts = _motion_matrix(model, K, self.motions)
        W = K.matMult(self.Q)
        k = int(self.starts[-1])

        def local(M):
            ia, ja, av = M.getValuesCSR()
            return scipy.sparse.csr_matrix((av, ja, ia), shape=(len(ia) - 1, k))

        # the Ritz matrices of every fibre, summed over the ranks
        product = (local(self.Q).T @ local(W)).tocsr()
        W.destroy()
        bounds = list(zip(self.starts[:-1], self.starts[1:]))
        blocks = np.concatenate([product[a:b, a:b].toarray().ravel() for a, b in bounds])
        blocks = model.comm.allreduce(blocks, op=MPI.SUM)
        offset = 0
        for a, b in bounds:
            n = b - a
            A = blocks[offset:offset + n * n].reshape(n, n)
            offset += n * n
            self.ritz.append(0.5 * (A + A.T))

    def destroy(self):
        if self.motions:
            self.Q.destroy()


def candidate_energies(model, K: PETSc.Mat) -> dict[int, np.ndarray]:
    """Per fibre with admissible candidates, the Ritz values (energies in
    the scaled metric of the module docstring) of K on them. Collective."""
    c = _Candidates(model, K)
    out = {f: np.linalg.eigvalsh(A) for (f, _), A in zip(c.motions, c.ritz)}
    c.destroy()
    return out


def zero_energy_motions(model, K: PETSc.Mat) -> list[ZeroMotion]:
    """The zero-energy motions of the scene with tangent K (see the module
    docstring). Collective."""
    c = _Candidates(model, K)
    if not c.motions:
        return []
    # multiplier rows: no diagonal term (a saddle point's constraint rows)
    diagonal = K.getDiagonal()
    multipliers = np.flatnonzero(diagonal.getArray(readonly=True) == 0.0)
    diagonal.destroy()
    scale = 1.0 / np.sqrt(c.sums[multipliers])
    found = []
    for (f, _), first, A in zip(c.motions, c.starts, c.ritz):
        energy, vectors = np.linalg.eigh(A)
        for j in np.flatnonzero(np.abs(energy) <= ZERO_MOTION_TOLERANCE):
            y = _combination(c.Q, int(first), vectors[:, j])
            pull = K.createVecLeft()
            K.mult(y, pull)
            held = np.sum((pull.getArray(readonly=True)[multipliers] * scale) ** 2)
            pull.destroy()
            if np.sqrt(model.comm.allreduce(held)) <= ZERO_MOTION_TOLERANCE:
                y.scale(1.0 / y.norm())
                found.append(ZeroMotion(f, _kind(model, y), y, float(energy[j])))
            else:
                y.destroy()
    c.destroy()
    return found


def _combination(Q: PETSc.Mat, first: int, coefficients: np.ndarray) -> PETSc.Vec:
    """Q c for c = ``coefficients`` on the columns first, first + 1, ..."""
    c = Q.createVecRight()
    c.set(0.0)
    lo, hi = c.getOwnershipRange()
    idx = np.arange(first, first + len(coefficients))
    mine = (idx >= lo) & (idx < hi)
    c.setValues(idx[mine].astype(PETSc.IntType), coefficients[mine])
    c.assemble()
    y = Q.createVecLeft()
    Q.mult(c, y)
    c.destroy()
    return y


def _kind(model, y: PETSc.Vec) -> str:
    """"spin" when the motion leaves every position in place, else "rigid"."""
    beam = model.beam_values(y)
    moved = np.abs(beam[:, 0:3]).max(initial=0.0)
    turned = np.abs(beam[:, 3:9]).max(initial=0.0)
    # positions are lengths, section vectors unit vectors: a turn of the
    # sections by theta with its positions in place to round-off
    length = max(f.length for f in model.mesh.fibres)
    return "spin" if moved <= ZERO_MOTION_TOLERANCE * turned * length else "rigid"


def describe(motions: list[ZeroMotion]) -> str:
    """One phrase for the warning: which fibres, which motions."""
    spins = sorted({m.fibre for m in motions if m.kind == "spin"})
    rigid = sorted({m.fibre for m in motions if m.kind == "rigid"})
    parts = []
    if spins:
        parts.append(f"the sections of fibre(s) {spins} spin freely about the fibre axis")
    if rigid:
        parts.append(f"fibre(s) {rigid} move rigidly with nothing to hold them")
    return " and ".join(parts)
