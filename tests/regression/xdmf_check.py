#!/usr/bin/env python3
"""The XDMF files of an MPM run folder against its run.h5.

  xdmf_check.py FOLDER [--grids N]

Every *.xdmf in FOLDER must be well-formed XML whose every HDF data item
names a dataset of run.h5 with exactly the stated dimensions; every grid's
Polyvertex count must match its geometry; every grid's Time must equal the
time dataset of its snapshot group (to the 8 significant digits written);
the snapshot groups of run.h5 must each appear in exactly one file, once.
--grids N: the files hold N grids in all. Exit 0 when all holds.
wellposed-mpm (1D) draws its particles on the x axis: its Y is the
function 0*$0 of the X item, checked like any other item.
"""
import glob
import os
import sys
import xml.etree.ElementTree as ET


def problems(folder, grids=None):
    """A list of what is wrong with the XDMF files of `folder` (empty: fine)."""
    import h5py
    out = []
    files = sorted(glob.glob(os.path.join(folder, "*.xdmf")))
    if not files:
        return ["no .xdmf file in " + folder]
    with h5py.File(os.path.join(folder, "run.h5"), "r") as h5:
        snapshot_groups = set()

        def collect(name, obj):
            if isinstance(obj, h5py.Dataset) and name.endswith("/time") and \
                    ("snapshots/" in name or "/snap_" in name):
                snapshot_groups.add(name[:-len("time")])
        h5.visititems(collect)
        seen, count = [], 0
        for path in files:
            label = os.path.basename(path)
            try:
                root = ET.parse(path).getroot()
            except ET.ParseError as e:
                out.append("%s: not XML (%s)" % (label, e))
                continue
            for grid in root.iter("Grid"):
                if grid.get("GridType") != "Uniform":
                    continue
                count += 1
                name = label + ":" + grid.get("Name", "?")
                n = int(grid.find("Topology").get("NumberOfElements"))
                groups = set()
                for item in grid.iter("DataItem"):
                    if item.get("Format") != "HDF":
                        continue
                    h5name, _, dset = item.text.strip().partition(":")
                    if h5name != "run.h5":
                        out.append("%s: data in %s, not run.h5" % (name, h5name))
                        continue
                    dset = dset.lstrip("/")
                    if dset not in h5:
                        out.append("%s: no dataset %s" % (name, dset))
                        continue
                    dims = tuple(int(d) for d in item.get("Dimensions").split())
                    if h5[dset].shape != dims:
                        out.append("%s: %s is %s, the XDMF says %s" % (name, dset,
                                                                       h5[dset].shape, dims))
                    if dims[0] != n:
                        out.append("%s: %s has %d rows for %d points" % (name, dset, dims[0], n))
                    groups.add(dset.rsplit("/", 1)[0] + "/")
                if len(groups) != 1:
                    out.append("%s: data from %d snapshot groups" % (name, len(groups)))
                    continue
                group = groups.pop()
                seen.append(group)
                t_xdmf = float(grid.find("Time").get("Value"))
                t_h5 = float(h5[group + "time"][0])
                if abs(t_xdmf - t_h5) > 1e-7 * max(abs(t_h5), 1e-300):
                    out.append("%s: Time %r, %stime holds %r" % (name, t_xdmf, group, t_h5))
        if sorted(seen) != sorted(snapshot_groups):
            missing = sorted(snapshot_groups - set(seen))
            twice = sorted({g for g in seen if seen.count(g) > 1})
            out.append("snapshot groups not described: %s; described twice: %s"
                       % (missing or "none", twice or "none"))
        if grids is not None and count != grids:
            out.append("%d grids in all, expected %d" % (count, grids))
    return out


def main(argv):
    if not argv or argv[0].startswith("-"):
        print(__doc__)
        return 2
    grids = int(argv[argv.index("--grids") + 1]) if "--grids" in argv else None
    found = problems(argv[0], grids)
    for p in found:
        print("FAIL: " + p)
    if not found:
        print("ok: the XDMF files of %s describe its run.h5" % argv[0])
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
