"""Regenerate the tables in the docs that come from the code (run after changing parameters).

python docs/update_tables.py
"""

from __future__ import annotations

import re
from pathlib import Path

from emaphm.params import parameter_table_markdown

DOCS = Path(__file__).parent
BLOCKS = {DOCS / "theory" / "hf-model.md": ("params", parameter_table_markdown)}


def render(text: str, name: str, table: str) -> str:
    pattern = re.compile(rf"(<!-- {name}:start -->\n).*?(<!-- {name}:end -->)", re.S)
    if not pattern.search(text):
        raise SystemExit(f"no <!-- {name}:start/end --> markers")
    return pattern.sub(lambda m: m.group(1) + table + m.group(2), text)


def main() -> None:
    for path, (name, make) in BLOCKS.items():
        path.write_text(render(path.read_text(), name, make()))
        print(f"updated {path}")


if __name__ == "__main__":
    main()
