"""Write the named workcells (`tamp.obstacles.SCENES`) as the scene files shipped in
tamp/world/scenes/ (`tamp.world.convert.workcells.write_workcells`). Run it after changing a
workcell in tamp/obstacles.py, and commit the files:

    python scripts/workcell_scenes.py [DIRECTORY]
"""

from __future__ import annotations

import sys

from tamp.world.convert.workcells import SCENES_DIR, write_workcells


def main(argv: list[str]) -> int:
    for path in write_workcells(argv[0] if argv else SCENES_DIR):
        print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
