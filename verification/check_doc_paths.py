"""Check that every path the documentation names exists (README.md, docs/, the READMEs under verification/),
and that every Rust name (`<module>::<item>`) and `src/…rs` path in a comment or a document exists
(tresca_py.docnames).

    .venv/bin/python verification/check_doc_paths.py [--root DIR]

Part of `make test`. Exits 1 and lists `doc:line: `ref` does not exist` for each missing reference.
"""

import argparse
import os
import sys

from tresca_py.doccheck import check, default_docs
from tresca_py.docnames import check_names


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--root", default=os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    args = ap.parse_args()
    docs = default_docs(args.root)
    missing = check(args.root, docs)
    stale = check_names(args.root)
    for m in missing + stale:
        print(m)
    print(f"doc paths: {len(docs)} documents, {len(missing)} missing reference(s); "
          f"Rust names and src/ paths in comments and documents: {len(stale)} stale")
    return 1 if missing or stale else 0


if __name__ == "__main__":
    sys.exit(main())
