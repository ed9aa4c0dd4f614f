"""The scaling model: per-rank memory and times for 1e7 and 1e8 unknowns from the D2 measurement."""
import math




def scaling_model(meas):
    """Per-rank memory and times for 1e7 and 1e8 unknowns on 16..256 ranks, from the -n 1/-n 2 data.

    Two measured points split the largest rank's peak into m(P) = c + D/P: D spreads over the ranks, c
    does not.  c minus the import footprint b (measured before the mesh exists) is what every rank holds in
    proportion to the mesh although it should not (host-side MUMPS analysis, per-rank index maps of global
    size ...); the model lets it grow ∝ n on every rank, which is pessimistic.  D grows like the factor
    (∝ n log2 n, 2D nested dissection) and is split over P ranks with a load imbalance of 1.3.  Times scale
    from the 1-rank measurement: factorisation ∝ n^1.5, solves ∝ n log2 n, C ∝ n_c x solve (an upper bound:
    MUMPS prunes the tree for selected entries of the inverse), parallel efficiency 0.5.
    """
    r1, r2 = meas["runs"]["1"], meas["runs"]["2"]
    n0 = r1["unknowns"]
    m1, m2 = max(r1["rss_time_mb"]), max(r2["rss_time_mb"])
    D = 2.0 * (m1 - m2)               # m(P) = c + D/P through the two points
    c = m1 - D
    b = float(r1["setup_peak_mb"][0].get("start", 155.0))
    st1 = r1["setup_times"]
    t_fact1 = st1["factorisation"]
    t_cond1 = st1["condensation"]
    t_step1 = r1["step_median"]
    nc0 = r1["n_contact"]
    rows = []
    for n in (1e7, 1e8):
        g_mem = (n / n0) * (math.log2(n) / math.log2(n0))
        g_flop = (n / n0) ** 1.5
        nc = math.sqrt(n / 6.0)
        g_cond = (nc / nc0) * g_mem
        C_mb = nc * nc * 8 / 2 ** 20
        for P in (16, 32, 64, 128, 256):
            mem = b + max(c - b, 0.0) * (n / n0) + D * g_mem / P * 1.3 + C_mb
            rows.append(dict(n=n, P=P, mem_gb=mem / 1024, mem_spread_gb=(b + D * g_mem / P * 1.3 + C_mb) / 1024,
                             fact_s=t_fact1 * g_flop / (P * 0.5), cond_s=t_cond1 * g_cond / (P * 0.5),
                             step_s=t_step1 * g_mem / (P * 0.5), nc=nc, C_mb=C_mb))
    return dict(c_mb=c, D_mb=D, b_mb=b, rows=rows, n0=n0)
