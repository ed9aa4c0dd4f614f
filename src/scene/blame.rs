//! What a displacement too large (or too small) to represent is linear in: the data the scene gives,
//! by name, for the messages that ask to scale them (the boundary values `u` and `gap` of a part impose
//! u there, so they are named first, then the loads, u₀ and the friction bounds).

use super::{PartKind, Scene};

impl Scene {
    /// "u is linear in X, Y and Z together, so scale them" (or "in X, so scale it") with `how`
    /// ("down" or "up"), naming exactly the nonzero data the scene gives.
    pub fn scale_data(&self, how: &str) -> String {
        let mut v: Vec<String> = Vec::new();
        let named = |p: &super::Part, key: &str| format!("part `{}`'s {key}", p.name);
        for p in &self.parts {
            match &p.kind {
                PartKind::Dirichlet(Some(_)) => v.push(named(p, "u")),
                PartKind::Contact(c) if c.gap.is_some() => v.push(named(p, "gap")),
                _ => {}
            }
        }
        if self.f.is_some() {
            v.push("the body force f".into());
        }
        v.extend(
            self.parts
                .iter()
                .filter(|p| match &p.kind {
                    PartKind::Neumann(g) => g.is_some(),
                    PartKind::Contact(c) => c.traction.is_some(),
                    PartKind::Dirichlet(_) => false,
                })
                .map(|p| named(p, "traction")),
        );
        if self.u0.is_some() {
            v.push("u₀".into());
        }
        // Coulomb's F is a ratio of forces: it does not scale with them
        v.extend(
            self.parts
                .iter()
                .filter(
                    |p| matches!(&p.kind, PartKind::Contact(c) if matches!(c.friction, super::FrictionLaw::Tresca(_))),
                )
                .map(|p| named(p, "g_a")),
        );
        match v.len() {
            0 => "the scene gives no data".into(),
            1 => format!("u is linear in {}, so scale it {how}", v[0]),
            n => format!("u is linear in {} and {} together, so scale them {how}", v[..n - 1].join(", "), v[n - 1]),
        }
    }
}
