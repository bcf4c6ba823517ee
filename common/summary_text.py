"""summary.txt of a wellposed run, for the plot scripts.

Each line is `key = value  # comment` (wellposed_summary); a figure that
does not apply reads `not_applicable  # why`.
"""
import os


def read_summary(folder):
    """{key: value text} of folder/summary.txt ({} when there is none)."""
    out = {}
    path = os.path.join(folder, "summary.txt")
    if os.path.exists(path):
        with open(path) as f:
            for line in f:
                key, eq, rest = line.partition("=")
                if eq:
                    out[key.strip()] = rest.split("#")[0].strip()
    return out
