"""Markdown to one self-contained HTML page, figures inlined, every report's form beside ``report.md``."""

from __future__ import annotations

import base64
import html
import re
from pathlib import Path

_STYLE = """
body { font-family: system-ui, sans-serif; max-width: 1200px; margin: 2em auto;
       padding: 0 1em; line-height: 1.45; color: #222; }
table { border-collapse: collapse; margin: 0.5em 0 1.5em; font-size: 0.86em; }
th, td { border: 1px solid #ccc; padding: 0.25em 0.5em; }
th { background: #f3f3f3; }
tr:nth-child(even) td { background: #fafafa; }
img { max-width: 100%; height: auto; border: 1px solid #eee; }
em { color: #555; }
"""


def render_html(markdown_text: str, base: str | Path, title: str = "stewartid report") -> str:
    """A self-contained HTML page from a report's Markdown, PNG figures inlined as base64.

    ``base``: the folder relative image paths refer to; ``title``: the page's ``<title>``."""
    from markdown_it import MarkdownIt

    base = Path(base)
    body = MarkdownIt("commonmark", {"html": False}).enable("table").render(markdown_text)

    def inline(match: re.Match[str]) -> str:
        source = html.unescape(match.group(1))
        path = base / source
        if source.startswith(("data:", "http:", "https:")) or not path.is_file():
            return match.group(0)
        data = base64.b64encode(path.read_bytes()).decode("ascii")
        mime = "image/svg+xml" if path.suffix == ".svg" else "image/png"
        return f'src="data:{mime};base64,{data}"'

    body = re.sub(r'src="([^"]+)"', inline, body)
    return (f"<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
            f"<title>{html.escape(title)}</title>\n<style>{_STYLE}</style>\n</head>\n"
            f"<body>\n{body}</body>\n</html>\n")


__all__ = ["render_html"]
