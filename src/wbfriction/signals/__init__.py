"""Log -> signals: measured velocities and accelerations (:mod:`.kinematics`, thesis 6.1.2), the
zero-phase filters (:mod:`.filters`, 7.1), support phases and masks (:mod:`.phases`, 5.3, 6.2.1),
contacts inferred from a raw walking log (:mod:`.contact_inference`), and spectra (:mod:`.spectrum`,
Fig. 7.1)."""

import lazy_loader

__getattr__, __dir__, __all__ = lazy_loader.attach_stub(__name__, __file__)
