"""Checks that an executed notebook drew its figures: `notebook_figures.py N notebook.ipynb` exits 1 (naming the
count) unless the notebook's code cells hold at least N image outputs."""
import json
import sys


def main():
    if len(sys.argv) != 3:
        sys.exit("usage: notebook_figures.py <minimum images> <executed notebook>")
    need, path = int(sys.argv[1]), sys.argv[2]
    with open(path, encoding="utf-8") as f:
        nb = json.load(f)
    images = sum(1 for c in nb["cells"] if c["cell_type"] == "code"
                 for o in c.get("outputs", []) if "image/png" in o.get("data", {}))
    print(f"{path}: {images} figures")
    if images < need:
        sys.exit(f"{path}: {images} figures drawn, {need} expected (is matplotlib installed?)")


main()
