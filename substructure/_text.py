"""User text as a figure shows it: plain text, never mathtext.

Matplotlib reads text between two dollar signs as mathematics (``$x$``),
so a name such as ``cutter $12`` or ``T$1$`` fails to draw or draws
wrongly.  Every name, label or title that comes from the user (an assembly,
a component, a point, a combination, a machine, a cut, a study, a joint)
goes through :func:`plain_text` where it is handed to matplotlib, once.
"""

from __future__ import annotations

import re
from typing import Any

__all__ = ["plain_text"]

_CONTROL = re.compile("[\x00-\x08\x0b\x0c\x0e-\x1f\x7f-\x9f\ud800-\udfff]")


def plain_text(text: Any) -> str:
    """``text`` as matplotlib draws it literally: ``$`` escaped, control characters as U+FFFD.

    Parameters
    ----------
    text : object
        A name, label or title (converted with ``str``); line ends are kept.

    Returns
    -------
    str
        The text to give a matplotlib ``Text`` (title, label, annotation,
        legend entry); apply it once, where the text enters the figure.
    """
    return _CONTROL.sub("\ufffd", str(text)).replace("$", r"\$")
