"""Names of :mod:`wbfriction.fleet`, imported on first use (:func:`lazy_loader.attach_stub`)."""

from .batch import BatchPlan as BatchPlan
from .batch import BatchSummary as BatchSummary
from .batch import plan_batch as plan_batch
from .batch import run_batch as run_batch
from .manifest import FolderScan as FolderScan
from .manifest import LogEntry as LogEntry
from .manifest import read_manifest as read_manifest
from .manifest import scan_folder as scan_folder
from .options import BatchOptions as BatchOptions
from .results import ResultsDataset as ResultsDataset
from .results import read_failures as read_failures
from .results import read_results as read_results
from .task import ResultKey as ResultKey
from .trends import FleetTrends as FleetTrends
from .trends import TrendOptions as TrendOptions
from .trends import fleet_trends as fleet_trends
