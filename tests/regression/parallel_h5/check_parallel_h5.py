"""Compare HDF5 files written through wellposed_h5_parallel with the serial
writer's reference: the same groups and datasets, each with the same type,
shape, storage layout, chunking, filters and fill value, bitwise the same
data, and the same attributes (type, shape, bytes).

    check_parallel_h5.py REFERENCE FILE [FILE ...]

Exit status 0 when every FILE matches, 1 otherwise (each difference is
printed). Uses h5py, which reads through Debian's serial HDF5, so a pass
also shows that files written by the parallel library read back serially.
"""
import sys

import h5py
import numpy as np


def describe(path):
    """Everything of a file that a reader can see, as comparable values."""
    items = {}
    with h5py.File(path, "r") as f:
        def attrs(obj):
            out = {}
            for name in obj.attrs:
                a = obj.attrs.get_id(name)
                value = np.asarray(obj.attrs[name])
                out[name] = (a.dtype.str, a.shape, value.tobytes())
            return out

        items["/"] = ("group", attrs(f))

        def visit(name, obj):
            if isinstance(obj, h5py.Dataset):
                plist = obj.id.get_create_plist()
                items[name] = (
                    "dataset",
                    obj.dtype.str,
                    obj.shape,
                    plist.get_layout(),
                    obj.chunks,
                    obj.compression,
                    tuple(plist.get_filter(i)[0] for i in range(plist.get_nfilters())),
                    np.asarray(obj.fillvalue).tobytes(),
                    obj[()].tobytes(),
                    attrs(obj),
                )
            else:
                items[name] = ("group", attrs(obj))

        f.visititems(visit)
    return items


def main(argv):
    if len(argv) < 3:
        print(__doc__)
        return 2
    reference = describe(argv[1])
    if len(reference) < 4:
        print(f"FAIL: the reference {argv[1]} holds too little ({sorted(reference)})")
        return 1
    failed = False
    for path in argv[2:]:
        other = describe(path)
        problems = []
        for name in sorted(set(reference) | set(other)):
            if name not in other:
                problems.append(f"{name}: missing")
            elif name not in reference:
                problems.append(f"{name}: not in the reference")
            elif reference[name] != other[name]:
                fields = ["kind", "type", "shape", "layout", "chunks", "compression",
                          "filters", "fill value", "data", "attributes"]
                if reference[name][0] != "dataset" or other[name][0] != "dataset":
                    fields = ["kind", "attributes"]
                diff = [fields[i] for i, (a, b) in enumerate(zip(reference[name], other[name]))
                        if a != b]
                problems.append(f"{name}: differs in {', '.join(diff)}")
        if problems:
            failed = True
            print(f"FAIL: {path}")
            for p in problems:
                print(f"  {p}")
        else:
            print(f"ok: {path} equals {argv[1]} ({len(other)} objects, data bitwise)")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
