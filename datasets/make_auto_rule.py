#!/usr/bin/env python3
"""Makes datasets/auto_rule.csv, the training table of the `auto` style.

Runs `parcelscope calibrate` (seed 1, default parameters) on each of the six
shared datasets and keeps, per observed block, its features (the f_ columns of
calibration.csv) and its calibrated style (style_after). Python 3 standard
library only; the calibrations do not depend on the table, so running it again
gives the same file.

    python3 datasets/make_auto_rule.py [--parcelscope build/release/parcelscope]
                                       [--datasets ../shared/datasets]
"""
import argparse
import csv
import os
import subprocess
import sys
import tempfile

# (city, file under the datasets folder, extra options), as docs/user/cli.md runs them.
CITIES = [
    ("cambridge_ma", "cambridge_ma/ASSESSING_ParcelsFY2014.topojson", ["--where", "ML <> 'ROAD'"]),
    ("paris_18e", "paris_18e/cadastre-75118-parcelles.json", []),
    ("malibu_ca", "malibu_ca/parcels.geojson", []),
    ("eatonville_wa", "eatonville_wa/parcels.geojson", ["--crs", "EPSG:2286"]),
    ("seoul_jamsil", "seoul_jamsil/parcels.geojson", []),
    ("rhone_69114", "rhone_69114/parcelles.json", []),
]
FEATURES = ["f_log_area", "f_box_ratio", "f_convexity", "f_access", "f_log_mean_area", "f_log_parcels",
            "f_log_aspect"]


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--parcelscope", default=os.path.join(here, "..", "build", "release", "parcelscope"))
    parser.add_argument("--datasets", default=os.path.join(here, "..", "..", "shared", "datasets"))
    parser.add_argument("--out", default=os.path.join(here, "auto_rule.csv"))
    args = parser.parse_args()
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for city, path, options in CITIES:
            source = os.path.join(args.datasets, path)
            if not os.path.exists(source):
                sys.exit(f"make_auto_rule: {source} is missing (the shared datasets are needed)")
            out = os.path.join(tmp, city)
            subprocess.run([args.parcelscope, "calibrate", source, "--out", out, "--seed", "1", "--figures", "0",
                            "--quiet"] + options, check=True)
            with open(os.path.join(out, "calibration.csv"), newline="") as f:
                for r in csv.DictReader(f):
                    rows.append([city, r["block_key"]] + [r[name] for name in FEATURES] + [r["style_after"]])
    with open(args.out, "w", newline="") as f:
        w = csv.writer(f, lineterminator="\n")
        w.writerow(["city", "block_key"] + FEATURES + ["style"])
        w.writerows(rows)
    print(f"{args.out}: {len(rows)} blocks from {len(CITIES)} datasets")


if __name__ == "__main__":
    main()
