"""The built-in robots: a TOML per robot (its URDF in example-robot-data or generated, its joints' roles,
contact frames, groups, friction and armature) and the generator of TORO-like's URDF (:mod:`.toro`).
Imports nothing: the command line lists them in its help."""

BUILTIN_ROBOTS = ("talos", "toro", "panda", "go2", "go2_walking", "go2_logged")
"""The robots ``--robot`` names (:func:`wbfriction.model.loading.load_robot`)."""
