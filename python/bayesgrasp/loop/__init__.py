"""The application's loop, between the planners and the experiments: what runs one grasp after
another on an object, in the simulator or with a robot outside.

:mod:`.context` (the run context, built once at the edge: hand, cache, success criterion, lift,
seed, progress), :mod:`.episode` (the closed loop in the simulator), :mod:`.outside_loop` and
:mod:`.outside_loop_category` (the same loops on disk, the robot outside: its interface),
:mod:`.vision_start` (the loop's start from a camera's view), :mod:`.category` (the category
pipeline: see, plan and execute, the demonstrated grasps of the training models) and
:mod:`.fusion_trial` (vision, then touch).

The experiments (:mod:`bayesgrasp.experiments`) and the commands (:mod:`bayesgrasp.cli`) import
from here; nothing here imports them. Importing the package loads none of its modules."""
