from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parents[1]


def test_every_requirement_is_pinned_and_mirrored_in_the_conda_env():
    reqs = [l.strip() for l in (ROOT / "requirements.txt").read_text().splitlines() if l.strip() and not l.startswith("#")]
    assert reqs and all("==" in r for r in reqs)
    env = yaml.safe_load((ROOT / "workflow" / "envs" / "contactid.yaml").read_text())
    pip = next(d["pip"] for d in env["dependencies"] if isinstance(d, dict))
    assert sorted(pip) == sorted(reqs)
