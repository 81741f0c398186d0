"""What every experiment's report step shares: the output directory and its summary.md /
summary.json, Markdown tables, CSV files and a headless matplotlib. Each experiment's statistics,
prose and figures are modules of their own (``*_stats``, ``*_prose`` / ``*_report``, ``*_plots``)."""
from __future__ import annotations

import csv
import json
from dataclasses import dataclass
from pathlib import Path
from typing import Dict, List, Sequence

import numpy as np


def by_object(results: list) -> Dict[str, list]:
    """Stored (key, result) pairs grouped by object: {object: [result, ...]}, objects sorted by name."""
    groups: Dict[str, list] = {}
    for k, r in results:
        groups.setdefault(k.object, []).append(r)
    return dict(sorted(groups.items()))


def mpl():
    """matplotlib.pyplot on the Agg backend (no display needed)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def save_figure(fig, path, tight: str = "layout") -> Path:
    """Writes ``fig`` to ``path`` at 110 dpi (laid out tightly first; tight="bbox": cropped to what
    is drawn instead), closes it and returns the path."""
    if tight == "layout":
        fig.tight_layout()
    fig.savefig(path, dpi=110, **({"bbox_inches": "tight"} if tight == "bbox" else {}))
    mpl().close(fig)
    return Path(path)


def markdown(rows: List[dict], cols: Sequence[str]) -> str:
    """A Markdown table of ``rows`` with columns ``cols`` (floats to three decimals, NaN as a dash)."""
    def fmt(v):
        if isinstance(v, float):
            return "–" if np.isnan(v) else f"{v:.3f}"
        return str(v)

    lines = ["| " + " | ".join(cols) + " |", "|" + "---|" * len(cols)]
    lines += ["| " + " | ".join(fmt(r[c]) for c in cols) + " |" for r in rows]
    return "\n".join(lines)


def write_csv(rows: List[dict], path: Path) -> None:
    """``rows`` as CSV (the first row's keys as the header); nothing for no rows."""
    if not rows:
        return
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)


@dataclass(frozen=True)
class Report:
    """What an experiment's report step wrote.

    out : Path — the directory holding summary.md, summary.json, the tables and the figures
    summary : dict — the content of summary.json (its keys differ per experiment)
    """

    out: Path
    summary: dict

    def to_dict(self) -> dict:
        return self.summary


def start(name: str, out) -> tuple:
    """(output directory, the summary.md lines so far, the summary dict) of experiment ``name``."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    return out, [f"# Experiment `{name}`", ""], {"experiment": name}


def finish(out: Path, md: list, summary: dict) -> Report:
    """Writes summary.md and summary.json; returns what was written where."""
    (out / "summary.md").write_text("\n".join(md))
    (out / "summary.json").write_text(json.dumps(summary, indent=1))
    return Report(out, summary)
