"""The README's quick start and .ci/run stay in step."""

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def quick_start_commands():
    text = (ROOT / "README.md").read_text()
    block = re.search(r"## Quick start\s+```bash\n(.*?)```", text, re.S).group(1)
    return [line for line in block.splitlines() if line.strip() and not line.startswith("#")]


def test_quick_start_has_exactly_two_commands():
    assert len(quick_start_commands()) == 2


def test_ci_runs_the_readme_test_command():
    ci = [line for line in (ROOT / ".ci" / "run").read_text().splitlines()
          if line.strip() and not line.startswith(("#", "set ", "cd "))]
    assert ci == [quick_start_commands()[1]]


def test_the_fields_section_names_every_file_field_and_sweep_write(tmp_path):
    """It had left out the field's events.csv and the sweep's sweep.toml."""
    from hybridtrack.fields import FieldResult
    from hybridtrack.sweep import sweep_files

    text = (ROOT / "README.md").read_text()
    section = re.search(r"## Fields, fast sun truth and sweeps\n(.*?)\n## ", text + "\n## ", re.S).group(1)
    written = [*FieldResult.files(tmp_path).values(), *sweep_files(tmp_path).values()]
    assert [path.name for path in written if f"{path.name}`" not in section] == []
