"""The documentation stays true: every public name has a docstring, every command shown in
README.md and docs/*.md names a command and options that exist, and the commands and Python
blocks of every page run.

Each page's shell commands and Python blocks run in page order, in a folder of their own
holding what the page assumes the reader has (``prepare``: a platform file, logged
experiments, the page's own mapping or study file), in this process (Python blocks that start
a dask cluster: in a fresh interpreter). A command runs as written unless:

- it would take minutes: it runs with the argument substitutions ``SCALED`` states (a shorter
  record, a smaller budget, a smaller study);
- it cannot run here (an install, the test suite itself, the site build, dask's own servers)
  or runs end to end elsewhere in the suite (``reproduce``): ``PARSED_ONLY`` names it with
  the reason, and it is only checked against the command's options (install commands: the
  extras they name exist).

README's quick start is the getting-started page's commands, which run there. A command
neither run nor listed fails ``test_every_documented_command_runs_or_is_listed``. Synopses
(``text`` blocks of ``stewartid ...`` with ``[--option]`` and ``a|b``) are not commands: they
are checked against the options only.
"""

from __future__ import annotations

import glob
import importlib
import inspect
import os
import pkgutil
import re
import shlex
import shutil
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest
import typer.main
from typer.testing import CliRunner

import stewartid
from stewartid.cli.application import app

ROOT = Path(__file__).resolve().parents[1]
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
COMMAND = typer.main.get_command(app)
FENCE = re.compile(r"^```(\w*)[^\n]*\n(.*?)^```", re.S | re.M)
SHELL = ("bash", "console", "sh", "shell")

#: Documented commands only checked against their options, (page, command): why they do not run.
PARSED_ONLY = {
    ("README.md", "pip install -e ."): "installs into the environment the tests run in",
    ("getting-started.md", "pip install -e ."): "installs into the environment the tests run in",
    ("README.md", 'pip install -e ".[test]"'): "installs into the environment the tests run in",
    ("README.md", "stewartid reproduce"): (
        "the full run takes minutes; the same command on shortened records, `stewartid reproduce "
        "--quick`, runs end to end in tests/test_reproduce.py (about 30 s)"),
    ("README.md", "python -m pytest"): "the test suite this test belongs to",
    ("user-guide.md", 'pip install -e ".[docs]"'): "installs into the environment the tests run in",
    ("user-guide.md", "python -m sphinx -W -b html docs/ docs/_build/html"): (
        "builds the whole site (minutes, the gallery included); .ci/run builds it"),
    ("studies.md", 'pip install "stewartid[dask]"'): "installs into the environment the tests run in",
    ("studies.md", "dask scheduler"): "dask's own server: it runs until stopped",
    ("studies.md", "OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 MKL_NUM_THREADS=1 dask worker "
                   "tcp://HOST:8786 --nworkers auto --nthreads 1"): (
        "dask's own worker: it runs until stopped, on the scheduler above"),
    ("studies.md", "stewartid study study.toml --out results/study --scheduler tcp://HOST:8786"): (
        "needs the scheduler and workers above; the same study runs on a local cluster by the "
        "page's first `study` command and on a stand-in cluster by the page's Python block"),
}

#: Argument substitutions of the commands and files that would take minutes as documented:
#: page -> [(documented text, text run)], applied to every command, Python block and prepared
#: file of the page.
SCALED = {
    # 120 s of motion played and predicted on 120 noise seeds: about 10 min; the smallest
    # budget that holds 2 levels at the quick design's 1 Hz, 2 seeds, model data
    "design.md": [("--budget 120", "--budget 36 --quick --seeds 2 --model-data --workers 1"),
                  # the physical design: 16 s of motion, no Monte Carlo check (about 15 s)
                  ("--budget 90", "--budget 16 --seeds 0")],
    # 6 x 20 s records: 2 s each
    "logs.md": [("--seed 1 --out rig/", "--seed 1 --duration 2 --out rig/")],
    # 3 x 3 grid points x 8 seeds of 6 x 20 s records: one point, one seed, 2 s records (the
    # page's Python block then resumes the study the command computed: no task is left)
    "studies.md": [("duration = 20.0", "duration = 2.0"), ("seeds = 8", "seeds = 1"),
                   ("coulomb = [0.0, 5.0, 30.0]", "coulomb = [5.0]"),
                   ("noise_scale = [0.0, 1.0, 2.0]", "noise_scale = [1.0]")],
    # the Python block's 6 x 6 s records: 2 s each (the commands keep 6 s: the report's
    # held-out validation needs more than 2 s, and figures, not the records, take its time)
    "getting-started.md": [("duration_s=6.0", "duration_s=2.0")],
    # the paper's six 20 s sines and the physical model on them: 8 s records
    "physical-model.md": [("--coulomb 30 --noise", "--coulomb 30 --noise --duration 8")],
    # the electric platform's six 20 s sines at 2 kHz, identified by every method: 6 s records
    "electric.md": [("--noise --seed 0 --out electric_run",
                     "--noise --seed 0 --duration 6 --out electric_run")],
}

#: A stand-in for dask-jobqueue (a batch system is not at hand): its cluster is a local one.
JOBQUEUE_STANDIN = '''"""dask_jobqueue of the documentation tests: a local cluster for the batch system."""
from distributed import LocalCluster


class SLURMCluster(LocalCluster):
    def __init__(self, **batch_options):
        super().__init__(n_workers=0, threads_per_worker=1, processes=False)

    def scale(self, jobs):
        super().scale(1)
'''


def blocks(page: Path, languages: tuple[str, ...]) -> list[str]:
    """The fenced code blocks of ``page`` in one of ``languages``, in page order."""
    return [body for language, body in FENCE.findall(page.read_text(encoding="utf-8"))
            if language in languages]


def shell_commands(block: str) -> list[str]:
    """The commands of a shell block: continuation lines joined, prompts and comments dropped,
    ``a && b`` split."""
    text = re.sub(r"\s*\\\n\s*", " ", block)
    out = []
    for line in text.splitlines():
        line = re.sub(r"^\s*\$\s+", "", line).split(" #")[0].strip()
        if line and not line.startswith("#"):
            out.extend(part.strip() for part in line.split("&&"))
    return out


def page_steps(page: Path) -> list[tuple[str, str]]:
    """``("shell", command)`` and ``("python", code)`` of ``page``, in page order."""
    steps = []
    for language, body in FENCE.findall(page.read_text(encoding="utf-8")):
        if language in SHELL:
            steps.extend(("shell", command) for command in shell_commands(body))
        elif language == "python":
            steps.append(("python", body))
    return steps


def all_commands() -> list[tuple[str, str]]:
    return [(page.name, command) for page in PAGES for kind, command in page_steps(page)
            if kind == "shell"]


def synopses() -> list[tuple[str, str]]:
    return [(page.name, command) for page in PAGES for block in blocks(page, ("text",))
            if block.startswith("stewartid ") for command in shell_commands(block)]


def module_names() -> list[str]:
    return ["stewartid", *(info.name for info in pkgutil.walk_packages(
        stewartid.__path__, prefix="stewartid.")
        if not any(part.startswith("_") for part in info.name.split(".")))]


# -- docstrings ----------------------------------------------------------------------------

def public_names(module) -> list[tuple[str, object]]:  # noqa: ANN001 - a module
    """The public functions and classes of ``module``: its ``__all__``, and every one defined in
    it whose name has no leading underscore; with the public methods and properties of each
    class (``Class.name``)."""
    names = set(getattr(module, "__all__", ())) | {
        name for name, value in vars(module).items() if not name.startswith("_")
        and (inspect.isclass(value) or inspect.isfunction(value))
        and getattr(value, "__module__", None) == module.__name__}
    found = []
    for name in sorted(names):
        value = getattr(module, name)
        if not (inspect.isclass(value) or inspect.isfunction(value) or inspect.ismodule(value)):
            continue  # constants are documented by the #: comment beside them
        found.append((name, value))
        if inspect.isclass(value) and value.__module__ == module.__name__:
            found += [(f"{name}.{member}", getattr(value, member))
                      for member, raw in vars(value).items() if not member.startswith("_")
                      and (inspect.isfunction(raw) or isinstance(raw, (property, classmethod,
                                                                        staticmethod)))]
    return found


@pytest.mark.parametrize("name", module_names())
def test_every_public_name_has_a_docstring(name: str) -> None:
    module = importlib.import_module(name)
    assert (module.__doc__ or "").strip(), f"module {name} has no docstring"
    missing = []
    for public, value in public_names(module):
        # an override documented by the method it overrides counts (inspect.getdoc)
        doc = (inspect.getdoc(value) or "").strip()
        # a dataclass without a docstring gets its signature as __doc__
        if not doc or (inspect.isclass(value) and doc.startswith(f"{value.__name__}(")):
            missing.append(public)
    assert missing == [], f"{name}: public names without a docstring: {missing}"


def test_the_docstring_check_covers_the_packages() -> None:
    names = module_names()
    assert {"stewartid.identification.registry", "stewartid.studies.runner",
            "stewartid.design.optimise", "stewartid.reports.identification.report"} <= set(names)


# -- the site ------------------------------------------------------------------------------

def test_every_registered_method_gets_an_api_page(tmp_path: Path) -> None:
    sys.path.insert(0, str(ROOT / "docs"))
    try:
        from method_pages import write_method_pages
    finally:
        sys.path.remove(str(ROOT / "docs"))
    from stewartid.identification.registry import registered_methods

    write_method_pages(tmp_path)
    specs = list(registered_methods())
    assert sorted(path.stem for path in tmp_path.glob("*.rst")) == sorted(
        ["index", *(spec.name for spec in specs)])
    for spec in specs:
        page = (tmp_path / f"{spec.name}.rst").read_text()
        cls = spec.estimator_class
        documented = f".. autoclass:: {cls.__module__}.{cls.__qualname__}" in page
        assert documented or f":ref:`method-{spec.preset_of}`" in page, spec.name


def test_the_gallery_has_six_examples_that_draw() -> None:
    examples = sorted((ROOT / "examples").glob("plot_*.py"))
    assert len(examples) >= 6
    for example in examples:
        text = example.read_text(encoding="utf-8")
        assert text.startswith('"""') and "plt.subplots(" in text, example.name


def test_readme_keeps_the_set_up_commands_and_ci_runs_its_test_command() -> None:
    readme = [block.strip() for block in blocks(ROOT / "README.md", SHELL)]
    install_and_run = "pip install -e . && stewartid reproduce"
    install_and_test = 'pip install -e ".[test]" && python -m pytest'
    assert install_and_run in readme and install_and_test in readme
    # each step on its own line, in the README's order: under `set -e` a failure inside an
    # && list would not stop the run
    steps = [line.strip() for line in (ROOT / ".ci" / "run").read_text().splitlines()]
    install, test = install_and_test.split(" && ")
    assert "set -euo pipefail" in steps
    assert install in steps and test in steps and steps.index(install) < steps.index(test)
    assert "python -m sphinx -W -b html docs/ \"$out\"" in steps


# -- commands: they exist ------------------------------------------------------------------

def test_the_pages_show_commands() -> None:
    found = {page for page, _ in all_commands()}
    assert {"README.md", "getting-started.md", "user-guide.md", "logs.md", "design.md",
            "studies.md"} <= found


def test_the_parsed_only_list_names_documented_commands() -> None:
    assert set(PARSED_ONLY) <= set(all_commands()), set(PARSED_ONLY) - set(all_commands())


def check_options(page: str, command: str) -> None:
    """``command`` names a stewartid command and options it has, or extras that exist."""
    words = shlex.split(command.replace("[", " ").replace("]", " "))
    while "=" in words[0] and not words[0].startswith("-"):
        words = words[1:]  # environment assignments
    if words[0] == "dask":
        assert (page, command) in PARSED_ONLY, f"{page}: {command!r}"
        return
    if words[:2] in (["pip", "install"], ["python", "-m"]) and "stewartid" not in words[:3]:
        extras = set(tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
                     ["optional-dependencies"])
        named = re.findall(r"\[(\w+)\]", command)
        assert set(named) <= extras, f"{page}: {command!r} names an extra that does not exist"
        return
    if words[:3] == ["python", "-m", "stewartid"]:
        words = words[2:]
    assert words[0] == "stewartid", f"{page}: not a stewartid command: {command!r}"
    words = words[1:]
    root_options = {option for parameter in COMMAND.params for option in parameter.opts}
    while words and words[0] in root_options:
        words = words[1:]
    name = words[0].split("|")[0]
    assert name in COMMAND.commands, f"{page}: {command!r}: no command {name!r}"
    options = {option for parameter in COMMAND.commands[name].params
               for option in (*parameter.opts, *parameter.secondary_opts)}
    unknown = [word.split("=")[0] for word in words[1:]
               if word.startswith("--") and word.split("=")[0] not in options]
    assert unknown == [], f"{page}: {command!r}: {name} has no option {unknown}"


@pytest.mark.parametrize(("page", "command"), all_commands() + synopses())
def test_a_documented_command_exists_with_its_options(page: str, command: str) -> None:
    check_options(page, command)


# -- commands and Python blocks: they run --------------------------------------------------

def run_python(code: str, folder: Path, path: tuple[Path, ...] = ()) -> subprocess.CompletedProcess:
    environment = {**os.environ, "MPLBACKEND": "Agg", "PYTHONPATH": os.pathsep.join(
        [*map(str, path), str(ROOT / "src"), os.environ.get("PYTHONPATH", "")])}
    return subprocess.run([sys.executable, "-c", code], cwd=folder, env=environment,
                          capture_output=True, text=True, timeout=600)


def scaled(page: str, text: str) -> str:
    for documented, run in SCALED.get(page, ()):
        text = text.replace(documented, run)
    return text


def run_command(page: str, command: str) -> str:
    """Run a documented ``stewartid`` command in the current folder, as a shell would (globs
    expanded), in this process."""
    words = shlex.split(scaled(page, command))
    if words[:3] == ["python", "-m", "stewartid"]:
        words = words[2:]
    assert words[0] == "stewartid", f"{page}: {command!r} is neither run nor in PARSED_ONLY"
    arguments = []
    for word in words[1:]:
        matches = sorted(glob.glob(word)) if "*" in word else [word]
        assert matches, f"{page}: {command!r}: nothing matches {word!r}"
        arguments.extend(matches)
    done = CliRunner().invoke(app, arguments)
    assert done.exit_code == 0, f"{page}: {command!r}:\n{done.output[-3000:]}"
    return done.output


@pytest.fixture(scope="module")
def logged(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """What the pages on one's own hexapod assume: ``my_hexapod.toml`` (the paper's platform
    file) and six logged experiments ``exp1.csv .. exp6.csv`` (2 s each, simulated)."""
    folder = tmp_path_factory.mktemp("logged")
    shutil.copy(ROOT / "src" / "stewartid" / "data" / "paper.toml", folder / "my_hexapod.toml")
    here = Path.cwd()
    os.chdir(folder)
    try:
        run_command("fixture", "stewartid simulate --platform my_hexapod.toml --coulomb 5 "
                    "--duration 2 --noise --seed 3 --out sim")
    finally:
        os.chdir(here)
    for path in (folder / "sim").glob("exp*.csv"):
        shutil.copy(path, folder / path.name)
    return folder


def write_controller_logs(folder: Path, page: Path) -> None:
    """The logs the page's mappings read, from ``exp*.csv``: ``log*.csv`` in the format of its
    "Worked mapping 1" (ms, mm, semicolons, decimal commas, no pose) with that mapping as
    ``controller_mm_ms.toml``, and ``mm/*.csv`` with the interchange names in ms and mm."""
    import numpy as np

    (mapping,) = [block for block in blocks(page, ("toml",))
                  if block.startswith("# controller_mm_ms.toml")]
    (folder / "controller_mm_ms.toml").write_text(mapping)
    (folder / "mm").mkdir()
    for k, path in enumerate(sorted(folder.glob("exp*.csv")), start=1):
        table = np.genfromtxt(path, delimiter=",", names=True)
        legs, forces = [f"l{j}" for j in range(1, 7)], [f"f{j}" for j in range(1, 7)]
        rows = np.column_stack([table["t"] * 1e3, *(table[name] * 1e3 for name in legs),
                                *(table[name] for name in forces)])
        header = ";".join(["Time [ms]", *(f"Leg{j} [mm]" for j in range(1, 7)),
                           *(f"F{j} [N]" for j in range(1, 7))])
        lines = [";".join(f"{value:.10g}".replace(".", ",") for value in row) for row in rows]
        (folder / f"log{k}.csv").write_text("\n".join([header, *lines]) + "\n")
        lines = [",".join(f"{value:.12g}" for value in row) for row in rows]
        (folder / "mm" / f"exp{k}.csv").write_text("\n".join([",".join(["t", *legs, *forces]),
                                                              *lines]) + "\n")


def prepare(page: str, folder: Path, logged: Path) -> tuple[Path, ...]:
    """Put in ``folder`` what ``page`` assumes exists; the extra import path of its Python blocks."""
    if page in ("logs.md", "user-guide.md"):
        for path in logged.glob("*.*"):
            shutil.copy(path, folder / path.name)
    if page == "logs.md":
        shutil.copytree(logged / "sim", folder / "clean")
        write_controller_logs(folder, ROOT / "docs" / page)
    if page == "physical-model.md":
        # the shipped platform file, and the same with the page's [payload] section
        shutil.copy(ROOT / "src" / "stewartid" / "data" / "paper.toml", folder / "paper.toml")
        (payload,) = [block for block in blocks(ROOT / "docs" / page, ("text",))
                      if block.startswith("[payload]")]
        (folder / "loaded.toml").write_text((folder / "paper.toml").read_text() + "\n"
                                            + payload)
    if page == "studies.md":
        (study,) = [block for block in blocks(ROOT / "docs" / page, ("toml",))
                    if block.startswith("[study]")]
        (folder / "study.toml").write_text(scaled(page, study))
        standin = folder / "standin"
        standin.mkdir()
        (standin / "dask_jobqueue.py").write_text(JOBQUEUE_STANDIN)
        return (standin,)
    return ()


def runnable_pages() -> list[str]:
    return [page.name for page in PAGES if page_steps(page)]


def test_every_documented_command_runs_or_is_listed() -> None:
    """Every command of a page with steps is a stewartid command (run by
    ``test_the_commands_and_python_blocks_of_a_page_run``) or in ``PARSED_ONLY``."""
    for page, command in all_commands():
        words = shlex.split(command)
        ran = words[0] == "stewartid" or words[:3] == ["python", "-m", "stewartid"]
        assert ran or (page, command) in PARSED_ONLY, (page, command)


@pytest.mark.slow
@pytest.mark.parametrize("page", runnable_pages())
def test_the_commands_and_python_blocks_of_a_page_run(
        page: str, tmp_path: Path, logged: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    source = ROOT / page if page == "README.md" else ROOT / "docs" / page
    steps = page_steps(source)
    if page == "README.md":
        # the quick start is the getting-started page's commands, which run there
        started = {c for kind, c in page_steps(ROOT / "docs" / "getting-started.md") if kind == "shell"}
        quick = [c for kind, c in steps if kind == "shell" and ("README.md", c) not in PARSED_ONLY]
        assert quick and set(quick) <= started, set(quick) - started
        assert [kind for kind, _ in steps if kind == "python"] == []
        return
    path = prepare(page, tmp_path, logged)
    monkeypatch.chdir(tmp_path)
    for kind, text in steps:
        if kind == "python" and "dask" in text:
            # a dask cluster outlives the block (and its client becomes the process's default):
            # a fresh interpreter
            done = run_python(scaled(page, text), tmp_path, path)
            assert done.returncode == 0, f"{page}: Python block\n{text}\n{done.stderr[-3000:]}"
        elif kind == "python":
            exec(compile(scaled(page, text), f"<{page}: Python block>", "exec"), {})
        elif (page, text) not in PARSED_ONLY:
            run_command(page, text)
    if page == "getting-started.md":
        assert (tmp_path / "result.json").is_file()
        assert (tmp_path / "report" / "report.html").is_file()
