"""wbfriction: whole-body joint friction estimation for torque-controlled legged robots.

The package follows the data flow, one subpackage per stage, each importing only those before it:

* :mod:`wbfriction.model`: the robot (URDF, joint roles, contact frames), its stance-rooted
  trees and constrained dynamics;
* :mod:`wbfriction.logs`: logs as files (Parquet, CSV, HDF5, ROS 2 bags), validated;
* :mod:`wbfriction.signals`: log -> signals: differentiation, zero-phase filters, support phases, spectra;
* :mod:`wbfriction.friction`: the friction models (thesis ch. 3), the estimate (5.10-5.13, 6.1),
  the fit (6.4), the energy check (7.9) and their documents;
* :mod:`wbfriction.inertia`: the inertia model identified from the same logs, sensitivity, URDF writing;
* :mod:`wbfriction.pipeline`: files in, files out (long logs in chunks, provenance);
* :mod:`wbfriction.report`: figures and the HTML report.

Beside them, :mod:`wbfriction.walking` plans walks and :mod:`wbfriction.sim` simulates them,
writing logs in the same format; :mod:`wbfriction.studies` reproduces the thesis's studies;
:mod:`wbfriction.cli` is the command line.

Sign convention: ``tau_f`` is the torque friction exerts on the joint,
``M qdd + h = S^T (tau + tau_f) + J^T lambda``; the model ``f(qd)`` of thesis eq. (3.5) is
fitted to ``-tau_f``.
"""

import lazy_loader

__getattr__, __dir__, __all__ = lazy_loader.attach_stub(__name__, __file__)
