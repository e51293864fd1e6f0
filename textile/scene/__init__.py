"""What the user builds: the scene.

- :mod:`textile.scene.model`: :class:`~textile.Model`, fibres with their
  prescribed unknowns, loads and effects, set up into one monolithic system;
- :mod:`textile.scene.loading`: schedules (how a quantity follows the load
  factor), handles and :class:`~textile.Stage`;
- :mod:`textile.scene.rigid_body`: :class:`~textile.RigidBody`, a body that
  drives fibre ends or block faces;
- :mod:`textile.scene.block_nodes`: the nodes of an elastic block that a
  rigid body holds;
- :mod:`textile.scene.scene_file`: a scene as a TOML file (``python3 -m
  textile run scene.toml``).
"""
