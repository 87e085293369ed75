"""The isolation table of a program beside the thesis tasks' (docs/simulation.md, "Your own programs").

Reads the Markdown tables `faultgen bench-isolators` writes (``STEM.md``) for one or more program
datasets and the thesis tasks' j2 table in docs/reproduction.md, and prints one table: isolator x wear
level, one column per task.

    python benchmarks/program_isolation_table.py pal-isolation.md:"palletize (irb6700)" palur5-isolation.md:"palletize (ur5)"
"""

from __future__ import annotations

import argparse
from pathlib import Path

ISOLATORS = ["te5", "te10", "cross_correlation", "granger", "trend", "pca_contribution"]
LEVELS = ["1", "5", "10", "15", "no fault"]
THESIS = ("pick_place", "spot_weld", "arc_weld")


def read(path: Path, stop: str | None = None) -> dict:
    """{(task, level, isolator): accuracy %} from a bench-isolators Markdown table (Table 6.2 layout)."""
    out = {}
    for line in path.read_text().splitlines():
        if stop and stop in line:
            break
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) == 14 and cells[1] in LEVELS:
            for isolator, value in zip(ISOLATORS, cells[8:], strict=True):
                out[(cells[0], cells[1], isolator)] = float(value)
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("tables", nargs="+", help="MD:COLUMN, a bench-isolators Markdown file and its column title")
    args = parser.parse_args()
    thesis = read(Path(__file__).parent.parent / "docs/reproduction.md", stop="Accuracy over the three tasks")
    columns = []
    for item in args.tables:
        path, _, title = item.partition(":")
        table = read(Path(path))
        (task,) = {key[0] for key in table}
        columns.append((title or task, {(level, iso): v for (_, level, iso), v in table.items()}))
    print("| isolator | wear % | " + " | ".join([*THESIS, *(t for t, _ in columns)]) + " |")
    print("| --- | --- | " + " | ".join(["---"] * (len(THESIS) + len(columns))) + " |")
    for isolator in ISOLATORS:
        for level in LEVELS:
            cells = [f"{thesis[(task, level, isolator)]:.1f}" for task in THESIS]
            cells += [f"{values[(level, isolator)]:.1f}" for _, values in columns]
            print(f"| {isolator} | {level} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
