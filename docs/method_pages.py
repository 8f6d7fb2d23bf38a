"""One page of the API reference per registered identification method, written from the
registry when the site is built (a new method gets its page without editing the docs)."""

from __future__ import annotations

from pathlib import Path


def method_page(spec) -> str:  # noqa: ANN001 - a MethodSpec
    """The reStructuredText of the page of one registered method."""
    cls = spec.estimator_class
    target = f"{cls.__module__}.{cls.__qualname__}"
    title = f"``{spec.name}``: {spec.display_name}"
    lines = [f".. _method-{spec.name}:", "", title, "=" * len(title), "",
             f"{spec.description[0].upper()}{spec.description[1:]}.", "",
             f"**Reference**: {spec.reference}", "",
             f"**Command line**: ``stewartid identify --method {spec.name} ...``", "",
             f"**Python**: ``create_identifier(\"{spec.name}\")`` builds a "
             f":class:`~{target}`"]
    if spec.preset_of is not None:
        settings = ", ".join(f"``{key}={value!r}``" for key, value in spec.defaults.items())
        lines[-1] += (f" with {settings}: a preset of :ref:`method-{spec.preset_of}`.")
        lines += [""]
    else:
        lines[-1] += "."
        lines += ["", f".. autoclass:: {target}", "   :members:", "   :inherited-members:",
                  "   :show-inheritance:", "   :no-index:", ""]
    return "\n".join(lines) + "\n"


def write_method_pages(folder: Path) -> None:
    """Write ``folder/<name>.rst`` for every registered method and ``folder/index.rst``
    listing them; a file is rewritten only when its text changes (Sphinx rereads it then)."""
    from stewartid.identification.registry import registered_methods

    folder.mkdir(parents=True, exist_ok=True)
    specs = list(registered_methods())
    pages = {f"{spec.name}.rst": method_page(spec) for spec in specs}
    title = "Identification methods"
    pages["index.rst"] = "\n".join(
        [title, "=" * len(title), "",
         "Every method of the registry (:mod:`stewartid.identification.registry`), one page "
         "each: what ``stewartid methods`` lists.", "", ".. toctree::", "   :maxdepth: 1", ""]
        + [f"   {spec.name}" for spec in specs]) + "\n"
    for name, text in pages.items():
        path = folder / name
        if not path.exists() or path.read_text() != text:
            path.write_text(text)
