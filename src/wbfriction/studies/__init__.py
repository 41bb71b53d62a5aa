"""The thesis's studies, reproduced: the simulation study of chapter 6 (:mod:`.simulation`,
``wbfriction demo``), the filter study of chapter 7 (:mod:`.filters`, ``wbfriction study-filters``),
the realistic-simulator study of 6.2 (:mod:`.realistic`, ``wbfriction demo --simulator mujoco``),
what they share (:mod:`.common`), and the thesis's own tables (:mod:`.thesis`)."""
