"""Fixtures shared by several test files."""
import pytest

from testkit import task_grasp_options


@pytest.fixture(scope="module")
def cat_options(tmp_path_factory):
    """Category options on small models of two training mugs with a few demonstrated top grasps."""
    return task_grasp_options(tmp_path_factory.mktemp("viewcat"))
