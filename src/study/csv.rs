//! The study as CSV: one row per level. Columns (empty where not computed):
//!
//! | columns | meaning |
//! |---|---|
//! | `energy_max`, `h1_max`, `l2_max` | true errors, max over the level's own time nodes ("max over n") |
//! | `energy_common`, `h1_common`, `l2_common` | true errors, max over the nodes common to all levels |
//! | `energy_T`, `h1_T`, `l2_T` | true errors at T |
//! | `consecutive_max`, `consecutive_T` | |||u_l − P u_{l−1}||| (the paper's), common nodes |
//! | `reference_max`, `reference_T` | error against the `--reference` run, common nodes |
//! | `est_max`, `est_T`, `gci` | estimated energy error (max over common nodes, at T) and GCI = 1.25 est_max |
//! | `p`, `beta`, `size` | the model of the three finest levels (order in `size` = h or k) |
//! | `verdict` | "in the asymptotic range" or "not yet: refine further (why)" |
//! | `<output>`, `<output>_est`, `<output>_gci`, `<output>_limit`, `<output>_p`, `<output>_verdict` | per scalar output |

use super::Study;
use crate::fem::norms::ErrorNorms;

fn quote(s: &str) -> String {
    format!("\"{}\"", s.replace('"', "\"\""))
}

/// The CSV text of a study.
pub fn text(s: &Study) -> String {
    let mut head = String::from(
        "refine,steps,h,k,dofs,paper_dofs,wall_s,iterations,energy_max,h1_max,l2_max,energy_common,h1_common,l2_common,\
         energy_T,h1_T,l2_T,consecutive_max,consecutive_T,reference_max,reference_T,norm_max,est_max,est_T,gci,p,beta,size,verdict",
    );
    for n in &s.output_names {
        head += &format!(",{n},{n}_est,{n}_gci,{n}_limit,{n}_p,{n}_verdict");
    }
    let f = |v: Option<f64>| v.filter(|x| x.is_finite()).map(|x| format!("{x:.10e}")).unwrap_or_default();
    let m = |a: Option<ErrorNorms>| [0, 1, 2].map(|i| f(a.map(|v| [v.energy, v.h1, v.l2][i]))).join(",");
    let c = |a: Option<[f64; 2]>| [0, 1].map(|i| f(a.map(|v| v[i]))).join(",");
    let e = &s.estimates;
    let mut out = head + "\n";
    for (l, r) in s.levels.iter().enumerate() {
        let est = e.levels.get(l);
        let verdict =
            est.map(|x| x.verdict.text()).or(e.refused.clone().map(|w| format!("not yet: refine further ({w})")));
        out += &format!(
            "{},{},{:.10e},{:.10e},{},{},{:.6},{},{},{},{},{},{},{:.10e},{},{},{},{},{},{},{}",
            r.refine,
            r.steps,
            r.h,
            r.k,
            r.dofs,
            r.paper_dofs,
            r.wall,
            r.iterations,
            m(r.max_err),
            m(r.common_err),
            m(r.final_err),
            c(r.consecutive),
            c(r.reference),
            r.norm_max,
            f(est.map(|x| x.error[0])),
            f(est.map(|x| x.error[1])),
            f(est.map(|x| x.gci)),
            f(e.model.map(|m| m.p)),
            f(e.model.map(|m| m.beta)),
            e.size,
            quote(&verdict.unwrap_or_default()),
        );
        for (i, o) in s.outputs.iter().enumerate() {
            let lv = o.levels.get(l);
            out += &format!(
                ",{},{},{},{},{},{}",
                f(r.outputs.get(i).copied()),
                f(lv.map(|v| v.0)),
                f(lv.map(|v| v.1)),
                f(o.model.map(|m| m.limit)),
                f(o.model.map(|m| m.p)),
                quote(&lv.map(|v| v.2.text()).unwrap_or_default())
            );
        }
        out.push('\n');
    }
    out
}
