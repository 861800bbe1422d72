"""``sixdof export``: a results file's time histories and frequency responses as UFF58 or CSV."""

from __future__ import annotations

from sixdof.io.exchange import export as export_results


def main(args, workers=None) -> int:
    files = export_results(args.results, args.out, args.format, args.what, args.point_quantity)
    print(f"Wrote {files[0].parent}: {', '.join(f.name for f in files)}")
    return 0
