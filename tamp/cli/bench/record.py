"""``tamp bench record``: benchmark results folders in, committed records, BENCHMARKS.md (whole)
and the README's "Current results" block out (`tamp.bench.record`). Exit 0; 2 on bad input."""

from __future__ import annotations

import argparse
import json

from tamp.bench.record import markdown


def record_command(args: argparse.Namespace) -> int:
    """Record ``--results`` folders into ``--into``, write ``--markdown`` and regenerate
    ``--readme``'s block."""
    readme = args.readme or None
    written = markdown.update(args.results, args.into, args.markdown, readme)
    if args.json:
        print(json.dumps([r.to_json() for r in written], indent=2))
        return 0
    for r in written:
        dirty = " (uncommitted changes)" if r.dirty else ""
        print(f"{r.name}: {markdown.label(r)} at {r.commit[:7]}{dirty}: {markdown.ours(r)}")
    also = f" and the table in {readme}" if readme else ""
    print(f"wrote {len(written)} record(s) to {args.into}; regenerated {args.markdown}{also}")
    return 0
