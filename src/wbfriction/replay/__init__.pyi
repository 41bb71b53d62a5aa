from .mjcf import Replay as Replay
from .mjcf import ReplayCheck as ReplayCheck
from .mjcf import replay_check as replay_check
from .mjcf import replay_mjcf as replay_mjcf
from .rollout import ActuatorParams as ActuatorParams
from .rollout import RolloutResult as RolloutResult
from .rollout import rollout as rollout
from .rollout import rollout_table as rollout_table
