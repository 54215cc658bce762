"""The example notebook runs in a real kernel, and a plain plt.plot renders after the project's plots."""

import os
from pathlib import Path

import pytest

nbclient = pytest.importorskip("nbclient")
nbformat = pytest.importorskip("nbformat")
pytest.importorskip("ipykernel")

NOTEBOOK = Path(__file__).parent.parent / "examples" / "notebook.ipynb"


def outputs_of(cell):
    return [key for output in cell.outputs for key in output.get("data", {})] + \
        [output.get("name", output["output_type"]) for output in cell.outputs]


def test_the_example_notebook_runs_and_pyplot_still_renders_afterwards():
    notebook = nbformat.read(NOTEBOOK, as_version=4)
    root = str(NOTEBOOK.parent.parent)
    env_path = os.environ.get("PYTHONPATH", "")
    os.environ["PYTHONPATH"] = root + (os.pathsep + env_path if env_path else "")  # this tree, in the kernel
    # a backend forced from outside (MPLBACKEND=Agg, as headless CI sets) would silence every notebook
    # plot whatever the project does; the kernel gets the notebook's own inline backend, as a user's would
    forced = os.environ.pop("MPLBACKEND", None)
    try:
        nbclient.NotebookClient(notebook, timeout=300, kernel_name="python3",
                                resources={"metadata": {"path": root}}).execute()
    finally:
        os.environ["PYTHONPATH"] = env_path
        if forced is not None:
            os.environ["MPLBACKEND"] = forced
    summary, figure, daily, explain, plain = notebook.cells[1:]
    assert "text/html" in outputs_of(summary) and "hybridtrack run" in summary.outputs[0]["data"]["text/plain"]
    assert "image/png" in outputs_of(figure)
    assert "text/html" in outputs_of(daily)
    assert "image/png" in outputs_of(explain) and "mode" in "".join(o.get("text", "") for o in explain.outputs)
    assert "image/png" in outputs_of(plain)  # the project's plots left pyplot's backend alone
