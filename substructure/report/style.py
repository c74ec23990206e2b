"""The report's style sheet, inline in the page: system fonts only, readable on screen and on paper."""

from __future__ import annotations

__all__ = ["STYLE"]

#: The CSS of the page (no ``url()``, no fonts fetched; ``<`` and ``&`` never appear, so the page stays XML).
STYLE = """
:root { --ink: #1d2430; --muted: #5b6575; --line: #d8dde5; --soft: #f4f6f9; --good: #1f7a3f;
        --goodbg: #e9f6ee; --warn: #9a5b00; --warnbg: #fff4e0; --bad: #a32020; --badbg: #fdeceb; }
* { box-sizing: border-box; }
body { margin: 0; color: var(--ink); background: #ffffff;
       font: 16px/1.5 system-ui, -apple-system, "Segoe UI", Roboto, "Helvetica Neue", Arial, sans-serif; }
header, main { max-width: 1080px; margin: 0 auto; padding: 0 24px; }
header { padding-top: 28px; border-bottom: 1px solid var(--line); }
h1 { font-size: 28px; margin: 0 0 4px 0; }
h2 { font-size: 22px; margin: 36px 0 10px 0; padding-bottom: 4px; border-bottom: 2px solid var(--ink); }
h3 { font-size: 17px; margin: 22px 0 6px 0; }
p { margin: 6px 0; }
.meta { color: var(--muted); font-size: 14px; }
nav ol { columns: 2; margin: 10px 0 16px 0; padding-left: 22px; font-size: 15px; }
a { color: #1a55a8; }
.answer { border: 2px solid var(--good); background: var(--goodbg); border-radius: 8px; padding: 14px 18px;
          margin: 12px 0; }
.answer.warn { border-color: var(--warn); background: var(--warnbg); }
.answer.neutral { border-color: var(--line); background: var(--soft); }
.answer .big { font-size: 22px; margin-bottom: 8px; }
.facts li { margin: 4px 0; }
.verdict { padding: 8px 12px; border-radius: 6px; display: block; }
.verdict.agrees, .verdict.explained { background: var(--goodbg); color: var(--good); }
.verdict.unexplained { background: var(--badbg); color: var(--bad); }
table { border-collapse: collapse; margin: 8px 0; font-size: 14px; min-width: 50%; }
th, td { border: 1px solid var(--line); padding: 4px 8px; text-align: left; vertical-align: top; }
th { background: var(--soft); font-weight: 600; }
tbody tr:nth-child(even) td { background: #fafbfc; }
table.wide { width: 100%; }
table.keyvalue thead { display: none; }
table.keyvalue td:first-child { font-weight: 600; background: var(--soft); white-space: nowrap; }
table.small { font-size: 12px; }
table.provenance td.source { font-size: 12px; color: var(--muted); }
table.provenance tr.flag td { background: var(--badbg); }
.band { border-left: 4px solid var(--warn); padding-left: 10px; }
figure { margin: 14px 0; }
figure img { max-width: 100%; height: auto; border: 1px solid var(--line); display: block; }
figcaption { font-size: 14px; color: var(--muted); margin-top: 4px; }
.note { font-size: 13px; color: var(--muted); }
.tech { font-size: 12px; color: var(--muted); font-family: ui-monospace, "SFMono-Regular", Menlo, Consolas, monospace; }
code { font-size: 13px; background: var(--soft); padding: 1px 4px; }
section { page-break-inside: auto; }
@media print {
  body { font-size: 12px; }
  nav { display: none; }
  h2 { page-break-after: avoid; }
  figure { page-break-inside: avoid; }
}
"""
