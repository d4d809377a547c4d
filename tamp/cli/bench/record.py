"""``tamp bench record``: benchmark results folders in, committed records and BENCHMARKS.md's
"Current results" table out (`tamp.bench.record`). Exit 0; 2 on bad input."""

from __future__ import annotations

import argparse
import json

from tamp.bench import record


def record_command(args: argparse.Namespace) -> int:
    """Record ``--results`` folders into ``--into`` and regenerate ``--markdown``'s table."""
    written = record.update(args.results, args.into, args.markdown)
    if args.json:
        print(json.dumps([r.to_json() for r in written], indent=2))
        return 0
    for r in written:
        dirty = " (uncommitted changes)" if r.dirty else ""
        print(f"{r.name}: {record.label(r)} at {r.commit[:7]}{dirty}: {record.ours(r)}")
    print(f"wrote {len(written)} record(s) to {args.into}; table regenerated in {args.markdown}")
    return 0
