"""The assembled system's bookkeeping: how the unknowns of every field are laid
out and which of them are constrained.

- :mod:`textile.system.layout`: the stacked layout of all fields (fibre
  nodes, matrix block, rigid bodies) over dolfinx index maps, the sparsity
  builder and the blocked matrix;
- :mod:`textile.system.constraint_set`: the one set of constrained unknowns
  (prescribed displacements and every effect's constraints) and their
  values at a load factor;
- :mod:`textile.system.dolfinx_core`: dolfinx's compiled core without its
  Python layer (the index maps and vectors the layout is built on).

The residual and tangent of the system are assembled by
:class:`textile.Model` (:mod:`textile.scene.model`) from the scene's effects.
"""
