"""``bayesgrasp objects``: list the built-in objects."""
from __future__ import annotations


def add(sub) -> None:
    sub.add_parser("objects", help="list the built-in objects",
                   description="Lists the built-in objects (names for --object and --scene-object).").set_defaults(run=run)


def run(args) -> int:
    from ..objects import list_objects

    for name in list_objects():
        print(name)
    return 0
