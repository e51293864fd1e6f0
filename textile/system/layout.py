"""The global system's unknowns: a stack of fields, each with its own index map.

A *field* is a block of unknowns with an MPI index map and a block size:
the fibres' nodes (block size 9: x0, g1, g2), a dolfinx function space of
the matrix (block size 3), rigid bodies, ... The global PETSc vector and
matrix stack the fields exactly as dolfinx's ``create_vector_block`` and
``create_matrix_block`` do, so dolfinx forms assemble into their block
unchanged:

- local numbering on a rank: [field 0 owned, field 0 ghosts, field 1 owned,
  field 1 ghosts, ...] (unrolled by block size);
- global numbering: rank-major, [rank 0: field 0 owned, field 1 owned |
  rank 1: ...].

Effects address unknowns through :meth:`DofLayout.local_dofs`, the local
(stacked) index of a field's unrolled local dofs.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from petsc4py import PETSc

from .dolfinx_core import load as _load_core

_cpp = _load_core()   # dolfinx's compiled core alone (textile.system.dolfinx_core)


@dataclass
class Field:
    """One block of unknowns: name, dolfinx IndexMap, block size."""

    name: str
    index_map: _cpp.common.IndexMap
    bs: int

    @property
    def size_local(self) -> int:
        """Owned unrolled dofs on this rank."""
        return self.index_map.size_local * self.bs

    @property
    def size_ghosted(self) -> int:
        """Owned plus ghost unrolled dofs on this rank."""
        return (self.index_map.size_local + self.index_map.num_ghosts) * self.bs


class DofLayout:
    """Stacked layout of several fields over one communicator."""

    def __init__(self, comm, fields: list[Field]):
        if not fields:
            raise ValueError("DofLayout: at least one field is needed")
        names = [f.name for f in fields]
        if len(set(names)) != len(names):
            raise ValueError(f"DofLayout: field names must be unique, got {names}")
        self.comm = comm
        self.fields = list(fields)
        self._index = {f.name: i for i, f in enumerate(fields)}
        sizes = [f.size_ghosted for f in fields]
        self._offsets = np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64)
        self.lgmap = PETSc.LGMap().create(self._stacked_l2g(), comm=comm)

    # -- fields -----------------------------------------------------------
    def field(self, name: str) -> Field:
        return self.fields[self._index[name]]

    def has(self, name: str) -> bool:
        return name in self._index

    def index(self, name: str) -> int:
        return self._index[name]

    @property
    def maps(self):
        """[(IndexMap, bs)] as dolfinx's block functions expect."""
        return [(f.index_map, f.bs) for f in self.fields]

    def local_dofs(self, name: str) -> np.ndarray:
        """Stacked local index of every unrolled local dof of field ``name``."""
        i = self._index[name]
        return np.arange(self._offsets[i], self._offsets[i + 1], dtype=np.int32)

    def offset(self, name: str) -> int:
        """Stacked local index of the field's first dof."""
        return int(self._offsets[self._index[name]])

    @property
    def size_local(self) -> int:
        return sum(f.size_local for f in self.fields)

    def owned_positions(self, stacked_local: np.ndarray) -> np.ndarray:
        """Map stacked local indices of owned dofs to positions in the owned
        part of the global vector (fields' owned blocks are contiguous)."""
        pos = np.empty_like(stacked_local)
        start_owned = 0
        for f in self.fields:
            off = self.offset(f.name)
            sel = (stacked_local >= off) & (stacked_local < off + f.size_local)
            pos[sel] = stacked_local[sel] - off + start_owned
            start_owned += f.size_local
        return pos

    @property
    def block_size(self) -> int:
        """The system matrix's block size: the largest that every field's
        block size is a multiple of (9 for fibres alone, 3 with a matrix's
        displacements, 1 with rigid bodies' multipliers). Every field's
        owned and ghost sizes, hence every rank's local size and every
        field's offset, are multiples of it, so each block of the stacked
        numbering is a node's dofs (or a part of them) in one field."""
        return math.gcd(*(f.bs for f in self.fields))

    def global_dofs(self, name: str, blocks: np.ndarray, owners: np.ndarray) -> np.ndarray:
        """Global (stacked) indices of the unrolled dofs of field ``name``'s
        global blocks ``blocks`` owned by ranks ``owners``: (n, bs) array.
        Lets an effect address unknowns that are not local (e.g. contact)."""
        i = self._index[name]
        bs = self.fields[i].bs
        info = self._rank_info
        base = np.array([info[r][0] + info[r][1][i] - bs * info[r][2][i]
                         for r in range(len(info))], dtype=np.int64)
        blocks = np.asarray(blocks, dtype=np.int64)
        return (base[np.asarray(owners)] + bs * blocks)[:, None] + np.arange(bs)

    # -- vectors ----------------------------------------------------------
    def create_vector(self) -> PETSc.Vec:
        """A ghosted global vector of the stacked layout."""
        return _cpp.fem.petsc.create_vector_block(self.maps)

    def get_local(self, x: PETSc.Vec) -> list[np.ndarray]:
        """Owned+ghost values of each field (x must be ghost-updated)."""
        return _cpp.la.petsc.get_local_vectors(x, self.maps)

    def scatter(self, b: PETSc.Vec, arrays: list[np.ndarray]) -> None:
        """Copy per-field local arrays (owned+ghost) into b (then reverse-add
        the ghost contributions with ``b.ghostUpdate``)."""
        _cpp.la.petsc.scatter_local_vectors(b, arrays, self.maps)

    # -- numbering --------------------------------------------------------
    def _stacked_l2g(self) -> np.ndarray:
        comm = self.comm
        sizes = [f.size_local for f in self.fields]
        rank_offset = comm.exscan(sum(sizes)) or 0
        field_offset = np.concatenate([[0], np.cumsum(sizes)[:-1]]).astype(np.int64)
        starts = [f.index_map.local_range[0] for f in self.fields]
        info = comm.allgather((rank_offset, field_offset, starts))
        self._rank_info = info
        out = []
        for i, f in enumerate(self.fields):
            out.append(rank_offset + field_offset[i] + np.arange(sizes[i], dtype=np.int64))
            ghosts, owners = f.index_map.ghosts, f.index_map.owners
            if len(ghosts):
                # global block index g owned by rank r sits at
                # rank_offset[r] + field_offset[r][i] + bs (g - start[r][i])
                base = np.array([info[r][0] + info[r][1][i] - f.bs * info[r][2][i]
                                 for r in owners], dtype=np.int64)
                out.append(((base + f.bs * np.asarray(ghosts))[:, None]
                            + np.arange(f.bs)).ravel())
        return np.concatenate(out).astype(PETSc.IntType)


class SparsityBuilder:
    """Nested sparsity pattern, one sub-pattern per pair of fields.

    Effects insert blocks with :meth:`insert` (field-local *block* indices,
    owned+ghost numbering); :meth:`create_matrix` assembles the pattern and
    returns an AIJ matrix with the layout's local-to-global map.
    """

    def __init__(self, layout: DofLayout):
        self.layout = layout
        # every block's pattern is made here, in the same order on every
        # rank: making one is collective (it duplicates the communicator),
        # and a rank without entries in a block (no beam element of its
        # own) would otherwise make that block at another moment than the
        # others and hang them
        fields = layout.fields
        self._patterns: dict[tuple[int, int], object] = {
            (i, j): _cpp.la.SparsityPattern(layout.comm, [fi.index_map, fj.index_map],
                                            [fi.bs, fj.bs])
            for i, fi in enumerate(fields) for j, fj in enumerate(fields)}
        self._filled: set[tuple[int, int]] = set()

    def set_pattern(self, row: str, col: str, pattern) -> None:
        """Use an existing (unassembled) dolfinx pattern for a block, e.g.
        ``fem.create_sparsity_pattern(form)`` for the matrix field. Must come
        before any insertion into that block (it would be lost). Collective
        when making the pattern is: call it on every rank."""
        key = (self.layout.index(row), self.layout.index(col))
        if key in self._filled:
            raise RuntimeError(f"sparsity block ({row}, {col}) already has entries: set_pattern "
                               "must come first (add the effect that owns the field first)")
        self._patterns[key] = pattern

    def pattern(self, row: str, col: str):
        """The block's pattern, to insert into (so set_pattern no longer may)."""
        key = (self.layout.index(row), self.layout.index(col))
        self._filled.add(key)
        return self._patterns[key]

    def insert(self, row: str, col: str, rows: np.ndarray, cols: np.ndarray) -> None:
        self.pattern(row, col).insert(np.asarray(rows, dtype=np.int32),
                                      np.asarray(cols, dtype=np.int32))

    def create_matrix(self) -> PETSc.Mat:
        layout = self.layout
        n = len(layout.fields)
        # empty sub-patterns cost nothing and keep the nested constructor simple
        grid = [[self._patterns[(i, j)] for j in range(n)] for i in range(n)]
        bs = [f.bs for f in layout.fields]
        pattern = _cpp.la.SparsityPattern(layout.comm, grid, [layout.maps, layout.maps], [bs, bs])
        pattern.assemble()
        # preallocated row by row (the nested pattern has block size 1), so
        # exactly; the block size, set after, is what MUMPS compresses the
        # graph with in its analysis (ICNTL(15) = -bs, set by PETSc): a
        # fibre-only tangent with block size 9 is ordered and factorized
        # faster than the same entries with block size 1 (a new ordering:
        # iterates change at round-off level). Matrices rebuilt for contact
        # keep block size 1 (Model.rebuild_matrix says why)
        A = _cpp.la.petsc.create_matrix(layout.comm, pattern)
        A.setBlockSizes(layout.block_size, layout.block_size)
        A.setLGMap(layout.lgmap, layout.lgmap)
        # an insertion outside the pattern is a bug in an effect's sparsity
        A.setOption(PETSc.Mat.Option.NEW_NONZERO_ALLOCATION_ERR, True)
        return A
