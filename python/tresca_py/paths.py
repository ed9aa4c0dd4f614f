"""Checks of the files the tools read and write, before any work: standard library only, so that ParaView's
own Python (``pvpython``, without the venv) runs them too (``tresca_py.paraview``).

* ``input_file``: exists, is a regular file (not a directory, FIFO or device: reading one could block or never
  end), is readable and not empty.
* ``hdf5_file``: an ``input_file`` that starts with the HDF5 signature and is not shorter than the end of file
  its superblock records (a truncated copy).
* ``output_file`` / ``output_dir``: the path is not a directory (or is one), its directory exists or can be
  made, and a file can be created in it (tried, so read-only directories and file systems are found even
  for root, whom the permission bits do not stop).
* ``new_output`` / ``distinct`` / ``write_new`` / ``write_named`` / ``output_subdir``: the rule of every file a
  tool writes, stated in docs/results.md ("Every output, one rule"; ``src/output/guard.rs`` for the Rust
  commands): checked before any work with ``lstat`` (never opened), compared with the inputs by
  ``(st_dev, st_ino)``, written through ``FILE.tmp``.
* ``sidecar_targets`` / ``check_sidecar``: the HDF5 files an XDMF sidecar references, and that it references
  the results file being opened (a ``run.h5`` copied with its ``run.xdmf`` keeps pointing at the original).
"""
import os
import stat
import xml.etree.ElementTree as ET

KINDS = ((stat.S_ISDIR, "a directory"), (stat.S_ISLNK, "a symbolic link"), (stat.S_ISFIFO, "a FIFO (named pipe)"),
         (stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"), (stat.S_ISSOCK, "a socket"))

HDF5_SIGNATURE = b"\x89HDF\r\n\x1a\n"
# a sidecar of the largest runs is a few MB; anything far larger is not one
MAX_SIDECAR_BYTES = 512 << 20


class PathError(ValueError):
    """A path a tool was given cannot be used; the message names the path and the problem."""


def input_file(path, what="results file"):
    """``path`` made absolute, if it names a readable, non-empty regular file."""
    try:
        st = os.stat(path)
    except FileNotFoundError:
        raise PathError(f"{path}: no such file ({what})") from None
    except OSError as err:
        raise PathError(f"{path}: cannot open the {what}: {err.strerror}") from None
    if stat.S_ISDIR(st.st_mode):
        raise PathError(f"{path}: is a directory, not a {what}")
    if not stat.S_ISREG(st.st_mode):
        raise PathError(f"{path}: is not a regular file (a FIFO, socket or device), not a {what}")
    if st.st_size == 0:
        raise PathError(f"{path}: is empty (0 bytes), not a {what}")
    try:
        with open(path, "rb"):
            pass
    except OSError as err:
        raise PathError(f"{path}: cannot read the {what}: {err.strerror}") from None
    return os.path.abspath(path)


def _superblock_eof(head):
    """The end of file a superblock records, as a size from the file's first byte (None for versions this does
    not know). HDF5 records it so with or without a user block before the superblock (a 512-byte user block
    and a file of 2,640 bytes record base address 512 and end of file 2,640): the superblock's offset is
    not added."""
    version = head[8]
    if version in (0, 1):
        size = head[13]  # size of offsets
        fixed = 24 + (4 if version == 1 else 0)  # signature .. file consistency flags (+ indexed storage K)
        at = fixed + 2 * size  # base address, free-space info address
    elif version in (2, 3):
        size = head[9]
        at = 12 + 2 * size  # signature, version, sizes, flags, base address, extension address
    else:
        return None
    if size not in (2, 4, 8):
        return None
    if len(head) < at + size:
        return at + size  # the file ends inside its superblock
    return int.from_bytes(head[at:at + size], "little")


def hdf5_file(path, what="results file"):
    """``input_file`` that is an HDF5 file of its recorded length (the superblock at byte 0, as tresca-cr and
    h5py write it, or at 512, 1024, ... after a user block)."""
    path = input_file(path, what)
    size = os.path.getsize(path)
    with open(path, "rb") as f:
        at = 0
        while at < size:
            f.seek(at)
            head = f.read(64)
            if head[:8] == HDF5_SIGNATURE:
                break
            at = 512 if at == 0 else 2 * at
        else:
            f.seek(0)
            start = f.read(16)
            kind = "a text file" if _is_text(start) else "binary data"
            raise PathError(f"{path}: is not an HDF5 file (no HDF5 signature; it starts with {start!r}: {kind}), "
                            f"not a {what}")
    eof = _superblock_eof(head)
    if eof is not None and eof > size:
        raise PathError(f"{path}: is truncated: its HDF5 superblock records at least {eof} bytes, the file "
                        f"has {size} (an interrupted copy?)")
    return path


def _is_text(b):
    try:
        text = b.decode("utf-8")
    except UnicodeDecodeError:
        return False
    return all(c.isprintable() or c in "\t\r\n" for c in text)


def output_dir(path, what="output directory"):
    """``path`` made absolute: an existing or creatable directory in which files can be created."""
    if os.path.exists(path) and not os.path.isdir(path):
        raise PathError(f"{path}: exists and is not a directory ({what})")
    try:
        os.makedirs(path, exist_ok=True)
    except OSError as err:
        raise PathError(f"{path}: cannot create the {what}: {err.strerror}") from None
    _probe(path, what)
    return os.path.abspath(path)


def output_file(path, what="output file"):
    """``path`` made absolute, if a file can be written there: not a directory (or other non-regular file),
    in a directory that exists or can be made and in which files can be created."""
    if os.path.isdir(path):
        raise PathError(f"{path}: is a directory; give a file name ({what})")
    if os.path.lexists(path) and not os.path.isfile(path):
        raise PathError(f"{path}: exists and is not a regular file ({what})")
    output_dir(os.path.dirname(os.path.abspath(path)), f"directory of the {what}")
    return os.path.abspath(path)


def _probe(directory, what):
    """Create and remove a file in ``directory``: the one test that read-only directories and file systems
    fail whoever runs it."""
    probe = os.path.join(directory, f".tresca-probe-{os.getpid()}")
    try:
        fd = os.open(probe, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o600)
    except OSError as err:
        raise PathError(f"{directory}: cannot create files in the {what}: {err.strerror}") from None
    os.close(fd)
    os.unlink(probe)


def kind_of(mode):
    """What a file system object of ``st_mode`` ``mode`` is, for messages."""
    return next((name for test, name in KINDS if test(mode)), "not a regular file")


def new_output(path, what="output file", force=False):
    """``path`` made absolute, if the rule of every output (module doc) lets a tool write it: absent, or with
    ``force`` a regular file with a single link; else PathError naming what is there."""
    try:
        st = os.lstat(path)
    except FileNotFoundError:
        return os.path.abspath(path)
    except OSError as err:
        raise PathError(f"{path}: cannot inspect the path for the {what}: {err.strerror}") from None
    if not stat.S_ISREG(st.st_mode):
        hint = "; give the path the link points to, or remove the link" if stat.S_ISLNK(st.st_mode) else ""
        raise PathError(f"{path}: the {what} would go here, but the path is {kind_of(st.st_mode)} (not a regular "
                        f"file){hint}")
    if st.st_nlink > 1:
        raise PathError(f"{path}: the {what} would go here, but the file there has {st.st_nlink} hard links "
                        "(replacing it would leave the other names as they are); remove it or give another path")
    if not force:
        raise PathError(f"{path}: the {what} already exists; pass --force to replace it")
    return os.path.abspath(path)


def _identity(path, follow):
    """``(st_dev, st_ino)`` of the file at ``path``, else of its directory with the name, else the absolute path."""
    try:
        st = os.stat(path) if follow else os.lstat(path)
        return st.st_dev, st.st_ino
    except OSError:
        pass
    try:
        st = os.stat(os.path.dirname(os.path.abspath(path)))
        return st.st_dev, st.st_ino, os.path.basename(path)
    except OSError:
        return os.path.abspath(path)


def distinct(outputs, inputs=()):
    """Refuse (PathError) an output that is the same file as an input or as another output, compared by
    ``(st_dev, st_ino)`` (a link or another name of a file counts). ``outputs``, ``inputs``: (path, what) pairs."""
    ids = [_identity(p, False) for p, _ in outputs]
    for p, what in inputs:
        i = _identity(p, True)
        if i in ids:
            out, owhat = outputs[ids.index(i)]
            raise PathError(f"{out}: the {owhat} would overwrite the input ({what} {p}); choose another path")
    for k, i in enumerate(ids):
        if i in ids[:k]:
            (a, awhat), (b, bwhat) = outputs[ids.index(i)], outputs[k]
            raise PathError(f"{b}: the {bwhat} and the {awhat} ({a}) are the same file: one would overwrite the "
                            "other; give them different paths")


def _fresh_tmp(path, what, tmp=None):
    """``tmp`` (default ``FILE.tmp``) beside ``path``, created exclusively without following links (a stale
    regular one is removed first): (its name, its open descriptor)."""
    tmp = tmp or path + ".tmp"
    try:
        st = os.lstat(tmp)
    except FileNotFoundError:
        st = None
    if st is not None:
        if not stat.S_ISREG(st.st_mode) or st.st_nlink > 1:
            there = kind_of(st.st_mode) if not stat.S_ISREG(st.st_mode) else f"a file with {st.st_nlink} hard links"
            raise PathError(f"{tmp}: the temporary of the {what} would be created here, but the path is {there} "
                            "(not one this program left); remove it")
        os.unlink(tmp)
    try:
        return tmp, os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_NOFOLLOW, 0o644)
    except OSError as err:
        raise PathError(f"{tmp}: cannot create the temporary of the {what}: {err.strerror}") from None


def write_new(path, write, what="output file", force=False):
    """Write the file ``path`` under the rule of every output: ``new_output`` again, then ``write(f)`` into
    ``FILE.tmp``, a binary file created exclusively without following links (a stale regular one is removed
    first), renamed over ``path``. A failure leaves no temporary and an old file as it was."""
    path = new_output(path, what, force)
    tmp, fd = _fresh_tmp(path, what)

    def fill():
        with os.fdopen(fd, "wb") as f:
            write(f)
    return _into_place(tmp, path, fill)


def write_named(path, write, what="output file", force=False):
    """``write_new`` for a writer that takes a file name, not a file (ParaView's screenshots, HDF5 files):
    ``write(tmp)`` writes the regular file ``FILE.tmp.EXT`` (the extension kept: writers choose the format by
    it) this call created exclusively, which must still be one (not replaced by a link or another kind of file)
    when it is renamed over ``path``."""
    path = new_output(path, what, force)
    root, ext = os.path.splitext(path)
    tmp, fd = _fresh_tmp(path, what, f"{root}.tmp{ext}")
    os.close(fd)

    def fill():
        write(tmp)
        st = os.lstat(tmp)
        if not stat.S_ISREG(st.st_mode) or st.st_nlink > 1:
            raise PathError(f"{tmp}: the temporary of the {what} was replaced by {kind_of(st.st_mode)} while it was "
                            "written; nothing was renamed into place")
    return _into_place(tmp, path, fill)


def _into_place(tmp, path, fill):
    """``fill()`` the temporary ``tmp``, then rename it over ``path``; on any failure the temporary is removed
    and ``path`` left as it was."""
    try:
        fill()
        os.replace(tmp, path)
    except BaseException:
        if os.path.lexists(tmp):
            os.unlink(tmp)
        raise
    return path


def output_subdir(path, what="output directory"):
    """``output_dir`` that is a directory itself, not a symbolic link to one (a tool that writes or removes files
    in it would do so wherever the link points)."""
    if os.path.islink(path):
        raise PathError(f"{path}: the {what} would go here, but the path is a symbolic link; give the directory it "
                        "points to, or remove the link")
    return output_dir(path, what)


def save_figure(fig, path, **kw):
    """``fig.savefig`` to ``path`` through ``write_new`` (whether an existing picture may be replaced was decided
    with the tool's other outputs before its work), in the format of its extension."""
    fmt = os.path.splitext(path)[1].lstrip(".").lower() or "png"
    return write_new(path, lambda f: fig.savefig(f, format=fmt, **kw), "picture", force=True)


def sidecar_targets(xdmf):
    """The HDF5 files (absolute, resolved against the sidecar's directory) that the XDMF file ``xdmf``
    references, and the names of its temporal collections."""
    xdmf = input_file(xdmf, "XDMF sidecar")
    if os.path.getsize(xdmf) > MAX_SIDECAR_BYTES:
        raise PathError(f"{xdmf}: is {os.path.getsize(xdmf)} bytes, too large for an XDMF sidecar")
    try:
        root = ET.parse(xdmf).getroot()
    except ET.ParseError as err:
        raise PathError(f"{xdmf}: is not an XDMF (XML) file: {err}") from None
    if root.tag != "Xdmf":
        raise PathError(f"{xdmf}: is XML but not XDMF (root element <{root.tag}>)")
    base = os.path.dirname(xdmf)
    files = set()
    for item in root.iter("DataItem"):
        if item.get("Format") == "HDF" and item.text and ":/" in item.text:
            name = item.text.strip().rsplit(":/", 1)[0]  # FILE:/dataset (a file name holds no "/")
            files.add(os.path.realpath(os.path.join(base, name)))
    blocks = [g.get("Name") for g in root.iter("Grid") if g.get("CollectionType") == "Temporal"]
    return files, blocks


def check_sidecar(h5, xdmf):
    """The block names of ``xdmf`` if it references exactly ``h5``; else PathError naming both."""
    files, blocks = sidecar_targets(xdmf)
    if not files:
        raise PathError(f"{xdmf}: references no HDF5 data: not a tresca-cr sidecar")
    h5r = os.path.realpath(h5)
    others = sorted(f for f in files if f != h5r)
    if others:
        missing = "" if os.path.exists(others[0]) else ", which does not exist"
        raise PathError(f"{xdmf}: the sidecar references {others[0]}{missing}, not {h5}: it belongs to another "
                        "results file (a copied or renamed pair); showing it would show that file's data")
    if "body" not in blocks:
        raise PathError(f"{xdmf}: has no 'body' collection (collections {blocks}): not a tresca-cr sidecar")
    return blocks
