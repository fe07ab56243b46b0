"""The demo's HTML report: every section's text and figures in one self-contained file."""

import base64
import html
import os
from pathlib import Path

_MEDIA = {".png": "image/png", ".gif": "image/gif"}

_STYLE = (
    "body{font-family:sans-serif;max-width:60em;margin:2em auto;padding:0 1em}"
    # pre-wrap: long lines (error messages, paths) wrap at the window's edge instead of being
    # cut off, while the spaces that align tables are kept
    "pre{background:#f6f6f6;padding:.8em;font-size:90%;white-space:pre-wrap;"
    "overflow-wrap:anywhere}"
    "figure{margin:1em 0}img{max-width:100%}figcaption{font-size:90%;color:#444}"
)


def _figure_html(path, description):
    media = _MEDIA.get(Path(path).suffix.lower(), "application/octet-stream")
    data = base64.b64encode(Path(path).read_bytes()).decode("ascii")
    return (
        f'<figure><img alt="{html.escape(description)}" src="data:{media};base64,{data}">'
        f"<figcaption>{html.escape(description)} ({html.escape(Path(path).name)})</figcaption>"
        "</figure>"
    )


def write_report(path, title, sections):
    """Write ``sections`` (title, lines, [(figure path, description)]) as one HTML file.

    Figures are embedded (base64), so the file can be mailed or moved alone. It is
    written under a temporary name in the same folder and renamed.
    """
    path = Path(path)
    parts = [
        "<!DOCTYPE html>",
        '<html lang="en"><head><meta charset="utf-8">',
        f"<title>{html.escape(title)}</title><style>{_STYLE}</style></head><body>",
        f"<h1>{html.escape(title)}</h1>",
    ]
    for heading, lines, figures in sections:
        parts.append(f"<h2>{html.escape(heading)}</h2>")
        parts.append("<pre>" + html.escape("\n".join(lines)) + "</pre>")
        parts += [_figure_html(p, d) for p, d in figures]
    parts.append("</body></html>")
    temporary = path.with_name(f".{path.name}.{os.getpid()}.part")
    try:
        temporary.write_text("\n".join(parts), encoding="utf-8")
        os.replace(temporary, path)
    finally:
        temporary.unlink(missing_ok=True)
    return path
