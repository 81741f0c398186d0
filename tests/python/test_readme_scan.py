"""The README's "Bring a scan" commands run as written, in order, on the YCB scans shipped in
tests/data/ycb, and do what the text says: the mass used is the one given, the label file is
written and the contacts then name the parts. Read from README.md, so the test breaks when the
README changes them."""
import json
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
README = (ROOT / "README.md").read_text()


def _commands():
    block = README.split("## Bring a scan", 1)[1].split("```sh", 1)[1].split("```", 1)[0]
    return [line for line in block.strip().splitlines() if line.strip()]


def test_bring_a_scan_runs_as_written(tmp_path):
    (tmp_path / "tests").symlink_to(ROOT / "tests")
    bg = os.path.join(os.path.dirname(sys.executable), "bayesgrasp")
    outputs = []
    for line in _commands():
        cmd = line.replace(".venv/bin/bayesgrasp", bg)
        p = subprocess.run(["bash", "-c", cmd], cwd=tmp_path, capture_output=True, text=True)
        assert p.returncode == 0, f"{line}\n{p.stderr[-2000:]}"
        outputs.append((line, p.stdout, p.stderr))
    mug, can, _, labels, labelled = outputs
    assert "object mass 0.118 kg, from given (--mass)" in mug[1]
    assert "lift test:" in mug[1] and "not watertight" not in mug[2]     # weighed: no warning about its volume
    doc = json.loads(can[1])
    assert doc["mass"]["kg"] == 0.349 and doc["lifted"] in (True, False)
    parts = json.loads((tmp_path / "out" / "mug_scan.parts.json").read_text())
    assert parts["parts"] == ["body", "rim", "handle"] and len(parts["faces"]) == 16384    # file order
    assert "wrote" in labels[1] and "handle" in labels[1]
    named = [l.split()[1] for l in labelled[1].splitlines() if l.startswith("    finger")]
    assert named and set(named) <= {"body", "rim", "handle"}
