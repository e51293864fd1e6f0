"""The assembled system of a scene: its unknowns, matrix and constraints.

- :mod:`textile.system.system`: :class:`~textile.system.system.System`,
  built from a closed scene (:class:`textile.Model`): the vectors and the
  matrix, the residual and tangent of the scene's effects, what the solver
  parts and the effects' hooks work on;
- :mod:`textile.system.layout`: the stacked layout of all fields (fibre
  nodes, matrix block, rigid bodies) over dolfinx index maps, the sparsity
  builder and the blocked matrix;
- :mod:`textile.system.constraint_set`: the one set of constrained unknowns
  (prescribed displacements and every effect's constraints) and their
  values at a load factor;
- :mod:`textile.system.dolfinx_core`: dolfinx's compiled core without its
  Python layer (the index maps and vectors the layout is built on).
"""
