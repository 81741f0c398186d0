"""GP models of the measurements P(M|A,O) and the stability P(S|A,O), learnt from simulation."""
from .grasp_models import GraspModels, ModelSettings, build_models, relative_top_grasps

__all__ = ["GraspModels", "ModelSettings", "build_models", "relative_top_grasps"]
