"""``sixdof examples``: the bundled scenarios copied into a folder."""

from __future__ import annotations

import os

from sixdof.examples import copy_examples


def main(args, workers=None) -> int:
    copied = copy_examples(args.folder)
    print(f"Copied {len(copied)} files into {args.folder}; run one with\n"
          f"  sixdof run {os.path.join(args.folder, 'bridge_beam_traffic.toml')}")
    return 0
