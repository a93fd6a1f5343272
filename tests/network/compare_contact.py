"""compare_contact.py REFERENCE.csv OTHER.csv: the contact.csv files of two runs of one case agree.

The pairs must be the same (same count, same x and y), and lambda1, lambda2, un1, un2 must agree
to 1e-12 relative: |a - b| <= 1e-12 max(|a|, |b|) for every pair. Prints the largest relative
difference of each column; exits 1 (naming the pair and column) when they do not agree.
"""
import csv
import sys

TOLERANCE = 1e-12
RESULT_COLUMNS = ("lambda1", "lambda2", "un1", "un2")


def read_rows(path):
    with open(path, newline="") as handle:
        rows = list(csv.DictReader(handle))
    if not rows:
        sys.exit(f"{path}: no contact pairs")
    return rows


def relative_difference(a, b):
    scale = max(abs(a), abs(b))
    return 0.0 if scale == 0.0 else abs(a - b) / scale


def main(reference_path, other_path):
    reference, other = read_rows(reference_path), read_rows(other_path)
    if len(reference) != len(other):
        sys.exit(f"{other_path}: {len(other)} pairs, {reference_path}: {len(reference)}")
    failures = []
    for column in ("x", "y"):
        scale = max(abs(float(row[column])) for row in reference) or 1.0
        for index, (a, b) in enumerate(zip(reference, other)):
            if abs(float(a[column]) - float(b[column])) > TOLERANCE * scale:
                failures.append(f"pair {index}: {column} {a[column]} != {b[column]}")
    largest = {}
    for column in RESULT_COLUMNS:
        largest[column] = 0.0
        for index, (a, b) in enumerate(zip(reference, other)):
            difference = relative_difference(float(a[column]), float(b[column]))
            largest[column] = max(largest[column], difference)
            if difference > TOLERANCE:
                failures.append(f"pair {index}: {column} {a[column]} vs {b[column]} "
                                f"(relative difference {difference:.3e})")
    print(f"{len(reference)} pairs; largest relative differences: " +
          ", ".join(f"{column} {value:.3e}" for column, value in largest.items()))
    if failures:
        print(f"{other_path} differs from {reference_path}:", *failures[:10], sep="\n  ")
        return 1
    return 0


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    sys.exit(main(sys.argv[1], sys.argv[2]))
