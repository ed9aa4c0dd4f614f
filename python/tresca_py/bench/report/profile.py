"""perf profiles of a run: the top symbols (self time) and the self time grouped by what it does."""
import os
import re
import subprocess

from tresca_py.common import ROOT


def perf_profile(cmd, tmp, label, freq=20000):
    data = os.path.join(tmp, f"perf_{label}.data")
    p = subprocess.run(["perf", "record", "-F", str(freq), "-g", "-o", data, "--"] + cmd,
                       capture_output=True, text=True, cwd=ROOT)
    if p.returncode != 0:
        return None, p.stderr[-500:]
    rep = subprocess.run(["perf", "report", "-i", data, "--stdio", "--no-children", "--sort", "symbol",
                          "-g", "none", "--percent-limit", "0.7"], capture_output=True, text=True).stdout
    lines = [re.sub(r"\s+-\s+-\s*$", "", ln.rstrip())[:160] for ln in rep.splitlines()
             if re.match(r"^\s+\d+\.\d+%", ln)]
    total = subprocess.run(["perf", "report", "-i", data, "--stdio", "--no-children", "--sort", "dso,symbol",
                            "-g", "none"], capture_output=True, text=True).stdout
    groups = {}
    for ln in total.splitlines():
        m = re.match(r"^\s+(\d+\.\d+)%\s+(\S+)\s+\[.\]\s+(.*)$", ln)
        if not m:
            continue
        pct, dso, sym = float(m.group(1)), m.group(2), m.group(3)
        groups[classify(dso, sym)] = groups.get(classify(dso, sym), 0.0) + pct
    return lines, groups


def classify(dso, sym):
    if "kernel" in dso:
        return "kernel (page faults, I/O, process start)"
    if "hdf5" in dso or "H5" in sym:
        return "HDF5 library"
    if dso.startswith("ld-") or sym.startswith("_dl_") or sym in ("do_lookup_x", "check_match", "strcmp"):
        return "dynamic loader (process start: relocations, symbol lookup)"
    if re.match(r"^(__)?(sin|cos|tan|exp|pow|log|atan)", sym):
        return "expression evaluation: libm (sin, cos, exp, pow)"
    if "expr::" in sym:
        return "expression evaluation: compiled program"
    if "libc" in dso or "libm" in dso:
        return "libc (memcpy, memset, malloc)"
    for key, name in [
        ("subtract_friction", "K⁻¹Eμ recovery of u (free::subtract_friction)"),
        ("LoadBasis::build", "load superposition set-up (superpose::LoadBasis::build)"),
        ("LoadBasis::response", "u_f = Σ c_j w_j (superpose::response)"),
        ("from_triplets", "sparse matrix from triplets (assembly)"),
        ("scatter", "assembly"),
        ("assemble", "assembly"),
        ("sort", "assembly (triplet sort)"),
        ("cholesky", "Cholesky (symbolic+numeric+solves)"),
        ("amd", "Cholesky (symbolic+numeric+solves)"),
        # Factor::with_ordering: faer's numeric factorisation inlined into it
        ("factor::", "Cholesky (symbolic+numeric+solves)"),
        ("pulp::", "faer SIMD kernels (pulp: factorisation updates, triangular solves)"),
        ("matvec", "sparse K·v (condition estimate, energies)"),
        ("llt", "Cholesky (symbolic+numeric+solves)"),
        ("gemm", "dense kernels (gemm, condensation)"),
        ("exmex", "expression evaluation: exmex interpreter"),
        ("forward_solve", "Cholesky (symbolic+numeric+solves)"),
        ("backward_solve", "Cholesky (symbolic+numeric+solves)"),
        ("loads::", "load assembly (scatter of the values)"),
        ("norms::", "error norms (sums)"),
        ("output", "results writer (Rust side)"),
        ("hdf5", "HDF5 library"),
        ("ssn", "friction QP (ssn/uzawa)"),
        ("uzawa", "friction QP (ssn/uzawa)"),
        ("contact", "friction QP (ssn/uzawa)"),
        ("finish", "finiteness check + errors (finish)"),
        ("Condensed::new", "condensation"),
    ]:
        if key.lower() in sym.lower():
            return name
    return "other"
