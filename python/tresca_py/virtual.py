"""Virtual datasets of HDF5 files the tools read: HDF5 reads a source that is missing (its file, or the dataset in
it) as the dataset's fill value, zeros, which would pass for data; ``missing_source`` finds such a source."""
import os

import h5py


def missing_source(ds):
    """``file:dataset`` of the first source of the virtual dataset ``ds`` that does not exist, else None."""
    here = os.path.dirname(os.path.abspath(ds.file.filename))
    for vs in ds.virtual_sources():
        src = vs.file_name
        if src == ".":
            found = isinstance(ds.file.get(vs.dset_name), h5py.Dataset)
        else:
            path = src if os.path.isabs(src) else os.path.join(here, src)
            found = os.path.isfile(path)
            if found:
                with h5py.File(path, "r") as f:
                    found = isinstance(f.get(vs.dset_name), h5py.Dataset)
        if not found:
            return f"{src}:{vs.dset_name}"
    return None
