//! The `tresca` group of docs/results.md (the layout every tool of the project reads), plus
//! `tresca/energy` (a_h(uⁿ,uⁿ)) and `tresca/contact/mu` (the friction force μ_e, kept bit-exact so
//! a resumed run is bit-identical; σ_τ = −μ/|e| alone would round) and `tresca/contact/dof` (the contact
//! unknown of uⁿ, equal to `slip` up to rounding).
//!
//! Time series (first axis = time node, allocated for all N + 1 steps at creation and filled as steps
//! are committed; rows beyond `completed` hold no data, and a stopped run is cut to its steps):
//! `times`, `u` (·, E, 2), `energy`, `steps/{iterations, residual, n_stick, n_slip, wall_time}`,
//! `contact/{slip, sigma_t, state, mu, dof}` (·, C) when Γ_C exists, `errors/{energy, h1, l2}` when `[exact]`,
//! and the energy audit of every step (`stepping::audit`, energy units: force × length per unit
//! thickness) `steps/{external_work, boundary_work, stored_energy, friction_dissipation,
//! euler_dissipation, balance_residual}`: (lⁿ,δuⁿ); the work of the reactions on Γ_D and of Γ_C's
//! imposed normal displacement (0 without boundary data); Eⁿ = ½a_h(uⁿ,uⁿ) (Dirichlet jump against
//! u_D); j_h(δuⁿ); ½a_h(δuⁿ,δuⁿ); and a_h(uⁿ,δuⁿ) + j_h(δuⁿ) − (lⁿ,δuⁿ) − boundary_work, which vanishes
//! up to rounding and the friction solver's tolerance (NaN where a step had no audit).
//!
//! With normal unknowns (a unilateral or Coulomb part, `friction::normal`) also
//! `contact/{pressure, gap, status}` (·, C): p_e = P_e/|e|, u·n(m_e) − ḡ_e and 0 stick, 1 slip,
//! 2 separated ([`NORMAL`]); they are not part of the checksum either (the files without them have none).
//!
//! `u` is the displacement at the edge midpoints, the lifting of the boundary data included
//! (`fem::lifting`); `energy` is a_h(uⁿ,uⁿ) with the Dirichlet jump measured against u_D.
//! `tresca/steps` carries the attribute `completed` (number of complete steps), written after every
//! other dataset of a step. `tresca/steps/checksum` (u64) holds per step the XXH64 (seed 0) of the step's
//! rows of every series above, in the order `times, u, energy, steps/{iterations, residual, n_stick, n_slip,
//! wall_time}, contact/{slip, sigma_t, state, mu, dof}, errors/{energy, h1, l2}` (those present), then the
//! audit series in [`AUDIT`]'s order, as little-endian bytes; it is written with the rows, before
//! `completed`, and checked by `--resume` and by `scripts/check_results.py` (`output::checksum`). Its
//! attribute `series` (`output::checksum::COVERS`) names the series it covers: a file written before the audit was covered has
//! no such attribute (and its checksums cover the series before the audit), and is read and resumed with
//! that layout. The unknown vector of the last step is rebuilt exactly from `u` (free
//! edges hold the two unknowns verbatim) and `contact/dof` (the one unknown of a contact edge).

use super::checksum::{covered, first_corrupt, rows_checksums, COVERS};
use super::h5::{attr, attr_str, attr_vec, put, read_str, Raw, Series};
use super::rows::Rows;
use super::Run;
use crate::fem::space::CrSpace;
use hdf5::{Attribute, File, Group};

mod read;

pub struct Tresca {
    pub group: Group,
    /// `steps` attribute `completed`, kept open: it is rewritten at every commit.
    completed: Attribute,
    times: Series,
    u: Series,
    energy: Series,
    iterations: Series,
    residual: Series,
    n_stick: Series,
    n_slip: Series,
    wall: Series,
    /// slip, sigma_t, state, mu, dof.
    contact: Option<[Series; 5]>,
    /// energy, h1, l2.
    errors: Option<[Series; 3]>,
    /// XXH64 of each step's rows (`None` in files of versions before it).
    checksum: Option<Series>,
    /// The energy audit, [`AUDIT`] (`None` in files of versions before it).
    audit: Option<Vec<Series>>,
    /// True if the checksums cover the audit series (attribute [`COVERS`] of the checksum).
    audit_checksummed: bool,
    /// [`NORMAL`] (`None` without normal unknowns).
    normal: Option<[Series; 5]>,
    /// α of a floating body (`super::rigid_series`; `None` without rigid motions).
    rigid: Option<Series>,
}

pub use super::checksum::AUDIT;
pub use super::normal_series::NORMAL;

const SCALARS: [&str; 6] = ["times", "energy", "steps/iterations", "steps/residual", "steps/n_stick", "steps/n_slip"];

/// The attributes of the `/tresca` group of a new file: the scene, the build, the solver and the sizes.
fn attributes(g: &Group, p: &Run) -> hdf5::Result<()> {
    let (s, mesh, space, loc) = (p.scene, p.mesh, p.space, &**g);
    attr_str(loc, "scene", &s.text)?;
    attr_str(loc, "scene_path", &s.file)?;
    attr_str(loc, "title", &s.title)?;
    attr_str(loc, "version", p.meta.version)?;
    attr_str(loc, "git_commit", p.meta.commit)?;
    attr(loc, "threads", crate::threads::count() as i64)?;
    attr_str(loc, "solver", s.solver.method.name())?;
    attr(loc, "tol", s.solver.tol)?;
    attr(loc, "max_iter", s.solver.max_iter() as i64)?;
    attr(loc, "uzawa_step", s.solver.uzawa_step)?;
    attr(loc, "rho", s.rho)?;
    attr(loc, "E", s.material.e)?;
    attr(loc, "nu", s.material.nu)?;
    attr(loc, "steps", p.n_steps() as i64)?;
    attr(loc, "n_edges", mesh.edges.len() as i64)?;
    attr(loc, "n_contact", space.contact.len() as i64)?;
    attr(loc, "n_dofs", space.n_dofs as i64)?;
    attr(loc, "paper_dofs", space.paper_dofs() as i64)?;
    attr(loc, "h", mesh.h_max())?;
    attr_vec(loc, "setup_times", &p.meta.setup.as_array())?;
    attr_str(loc, "setup_times_meaning", "mesh+space, assembly, factorisation, load superposition, condensation (s)")?;
    attr_str(loc, "status", "running")?;
    Ok(())
}

impl Tresca {
    /// Create the group with static data, attributes and empty series.
    pub fn create(file: &File, p: &Run) -> hdf5::Result<Tresca> {
        let g = file.create_group("tresca")?;
        let (mesh, space) = (p.mesh, p.space);
        let mg = g.create_group("mesh")?;
        let pts: Vec<f64> = mesh.points.iter().flatten().copied().collect();
        put(&mg, "points", &[mesh.points.len(), 2], &pts)?;
        let tris: Vec<i64> = mesh.tris.iter().flatten().map(|&v| v as i64).collect();
        put(&mg, "triangles", &[mesh.tris.len(), 3], &tris)?;
        let edges: Vec<i64> = mesh.edges.iter().flatten().map(|&v| v as i64).collect();
        put(&mg, "edges", &[mesh.edges.len(), 2], &edges)?;
        let mids: Vec<f64> = (0..mesh.edges.len()).flat_map(|e| mesh.midpoint(e)).collect();
        put(&mg, "midpoints", &[mesh.edges.len(), 2], &mids)?;
        let ne = mesh.edges.len();
        let sc = p.n_steps() + 1;
        let sg = g.create_group("steps")?;
        let contact = if space.contact.is_empty() {
            None
        } else {
            let cg = g.create_group("contact")?;
            let c = &space.contact;
            let nc = c.len();
            put(&cg, "edges", &[nc], &c.iter().map(|c| c.edge as i64).collect::<Vec<_>>())?;
            put(&cg, "normal", &[nc, 2], &c.iter().flat_map(|c| c.normal).collect::<Vec<_>>())?;
            put(&cg, "tangent", &[nc, 2], &c.iter().flat_map(|c| c.tangent).collect::<Vec<_>>())?;
            put(&cg, "g", &[nc], &c.iter().map(|c| c.g_mean).collect::<Vec<_>>())?;
            Some([
                Series::create::<f64>(&cg, "slip", 1, &[nc], sc)?,
                Series::create::<f64>(&cg, "sigma_t", 1, &[nc], sc)?,
                Series::create::<u8>(&cg, "state", 1, &[nc], sc)?,
                Series::create::<f64>(&cg, "mu", 1, &[nc], sc)?,
                Series::create::<f64>(&cg, "dof", 1, &[nc], sc)?,
            ])
        };
        let normal = super::normal_series::create(&g, space, sc)?;
        let rigid = super::rigid_series::create(&g, p.rigid, sc)?;
        let errors = if p.meta.true_errors {
            let eg = g.create_group("errors")?;
            Some([
                Series::create::<f64>(&eg, "energy", 1, &[], sc)?,
                Series::create::<f64>(&eg, "h1", 1, &[], sc)?,
                Series::create::<f64>(&eg, "l2", 1, &[], sc)?,
            ])
        } else {
            None
        };
        attributes(&g, p)?;
        attr(&sg, "completed", 0i64)?;
        let audit = AUDIT.iter().map(|a| Series::create::<f64>(&sg, a, 1, &[], sc)).collect::<hdf5::Result<_>>()?;
        let checksum = Series::create::<u64>(&sg, "checksum", 1, &[], sc)?;
        attr_str(&checksum.ds, COVERS, &covered(contact.is_some(), errors.is_some()))?;
        Ok(Tresca {
            normal,
            rigid,
            audit: Some(audit),
            audit_checksummed: true,
            checksum: Some(checksum),
            times: Series::create::<f64>(&g, "times", 1, &[], sc)?,
            u: Series::create::<f64>(&g, "u", 1, &[ne, 2], sc)?,
            energy: Series::create::<f64>(&g, "energy", 1, &[], sc)?,
            iterations: Series::create::<i64>(&sg, "iterations", 1, &[], sc)?,
            residual: Series::create::<f64>(&sg, "residual", 1, &[], sc)?,
            n_stick: Series::create::<i64>(&sg, "n_stick", 1, &[], sc)?,
            n_slip: Series::create::<i64>(&sg, "n_slip", 1, &[], sc)?,
            wall: Series::create::<f64>(&sg, "wall_time", 1, &[], sc)?,
            contact,
            errors,
            completed: sg.attr("completed")?,
            group: g,
        })
    }

    /// Open the group of an existing file.
    pub fn open(file: &File) -> hdf5::Result<Tresca> {
        let g = file.group("tresca")?;
        let sg = g.group("steps")?;
        let contact = match g.group("contact") {
            Ok(cg) => Some([
                Series::open(&cg, "slip", 1)?,
                Series::open(&cg, "sigma_t", 1)?,
                Series::open(&cg, "state", 1)?,
                Series::open(&cg, "mu", 1)?,
                Series::open(&cg, "dof", 1)?,
            ]),
            Err(_) => None,
        };
        let errors = match g.group("errors") {
            Ok(eg) => Some([Series::open(&eg, "energy", 1)?, Series::open(&eg, "h1", 1)?, Series::open(&eg, "l2", 1)?]),
            Err(_) => None,
        };
        let checksum = Series::open(&sg, "checksum", 1).ok();
        let normal = super::normal_series::open(&g);
        Ok(Tresca {
            normal,
            rigid: super::rigid_series::open(&g),
            audit: AUDIT.iter().map(|a| Series::open(&sg, a, 1)).collect::<hdf5::Result<_>>().ok(),
            audit_checksummed: checksum.as_ref().is_some_and(|c| c.ds.attr(COVERS).is_ok()),
            checksum,
            times: Series::open(&g, SCALARS[0], 1)?,
            u: Series::open(&g, "u", 1)?,
            energy: Series::open(&g, SCALARS[1], 1)?,
            iterations: Series::open(&g, SCALARS[2], 1)?,
            residual: Series::open(&g, SCALARS[3], 1)?,
            n_stick: Series::open(&g, SCALARS[4], 1)?,
            n_slip: Series::open(&g, SCALARS[5], 1)?,
            wall: Series::open(&g, "steps/wall_time", 1)?,
            contact,
            errors,
            completed: sg.attr("completed")?,
            group: g,
        })
    }

    /// Every series in the checksum's order, the audit's last when `audit`.
    fn series(&mut self, audit: bool) -> Vec<&mut Series> {
        let mut v = vec![
            &mut self.times,
            &mut self.u,
            &mut self.energy,
            &mut self.iterations,
            &mut self.residual,
            &mut self.n_stick,
            &mut self.n_slip,
            &mut self.wall,
        ];
        v.extend(self.contact.iter_mut().flatten());
        v.extend(self.errors.iter_mut().flatten());
        if audit {
            v.extend(self.audit.iter_mut().flatten());
        }
        v
    }

    /// The first series whose rows are not as wide as `space` needs (`u` 2 values an edge, the contact
    /// series one a Γ_C edge, the rest one a step) or that has no room for the `completed` steps, named
    /// with both figures; a file damaged or forged after it was written, whose rows a warm start would
    /// misread.
    pub fn misfit(&self, space: &CrSpace, completed: usize) -> Option<String> {
        let (ne, nc) = (space.edge_dof.len(), space.contact.len());
        let one =
            [&self.times, &self.energy, &self.iterations, &self.residual, &self.n_stick, &self.n_slip, &self.wall];
        let one = one.into_iter().chain(self.errors.iter().flatten()).chain(self.audit.iter().flatten());
        let per_edge = self.contact.iter().chain(&self.normal).flatten().map(|s| (s, vec![nc]));
        let all = std::iter::once((&self.u, vec![ne, 2])).chain(per_edge);
        let mut all = all.chain(one.chain(&self.checksum).map(|s| (s, vec![])));
        all.find_map(|(s, want)| match (s.rest() != want.as_slice(), s.capacity() < completed) {
            (true, _) => {
                Some(format!("{} holds rows of shape {:?}, this run's mesh needs {want:?}", s.ds.name(), s.rest()))
            }
            (_, true) => Some(format!("{} holds {} steps, {completed} were committed", s.ds.name(), s.capacity())),
            _ => None,
        })
    }

    /// The first of the `completed` stored steps whose rows do not match their checksum, if any; an
    /// error if the file has no checksums.
    pub fn first_corrupt_step(&mut self, completed: usize) -> hdf5::Result<Option<usize>> {
        let stored: Vec<u64> = match &self.checksum {
            Some(c) => c.read_steps::<u64>(0, completed)?,
            None => return Err(hdf5::Error::from("the file has no step checksums (written before they were added)")),
        };
        if self.audit_checksummed && self.audit.is_none() {
            return Err(hdf5::Error::from("its energy audit series are missing, though its checksums cover them"));
        }
        first_corrupt(&stored, &self.series(self.audit_checksummed), completed)
    }

    /// The `completed` attribute.
    pub fn completed(&self) -> hdf5::Result<usize> {
        Ok(self.completed.read_scalar::<i64>()?.max(0) as usize)
    }

    /// Append buffered rows (all series; `completed` is not changed).
    pub fn write_rows(&self, raw: &Raw, b: &Rows) -> hdf5::Result<()> {
        let (n, k) = (b.first, b.count);
        if let Some(c) = &self.checksum {
            let kinds = (self.contact.is_some(), self.errors.is_some(), self.audit_checksummed);
            c.write_steps(raw, n, k, &rows_checksums(b, kinds))?;
        }
        self.times.write_steps(raw, n, k, &b.times)?;
        self.u.write_steps(raw, n, k, &b.u)?;
        self.energy.write_steps(raw, n, k, &b.energy)?;
        self.iterations.write_steps(raw, n, k, &b.iterations)?;
        self.residual.write_steps(raw, n, k, &b.residual)?;
        self.n_stick.write_steps(raw, n, k, &b.n_stick)?;
        self.n_slip.write_steps(raw, n, k, &b.n_slip)?;
        self.wall.write_steps(raw, n, k, &b.wall)?;
        if let Some([slip, sig, state, mu, d]) = &self.contact {
            slip.write_steps(raw, n, k, &b.slip)?;
            sig.write_steps(raw, n, k, &b.sigma_t)?;
            state.write_steps(raw, n, k, &b.state)?;
            mu.write_steps(raw, n, k, &b.mu)?;
            d.write_steps(raw, n, k, &b.dof)?;
        }
        if let Some(es) = &self.errors {
            for (s, v) in es.iter().zip(&b.errors) {
                s.write_steps(raw, n, k, v)?;
            }
        }
        if let Some([p, g, st, f, nd]) = &self.normal {
            p.write_steps(raw, n, k, &b.pressure)?;
            g.write_steps(raw, n, k, &b.gap)?;
            st.write_steps(raw, n, k, &b.status)?;
            f.write_steps(raw, n, k, &b.force)?;
            nd.write_steps(raw, n, k, &b.normal_dof)?;
        }
        if let Some(s) = &self.rigid {
            s.write_steps(raw, n, k, &b.rigid)?;
        }
        if let Some(a) = &self.audit {
            for (s, v) in a.iter().zip(&b.audit) {
                s.write_steps(raw, n, k, v)?;
            }
        }
        Ok(())
    }

    /// Mark `count` steps complete.
    pub fn set_completed(&self, count: usize) -> hdf5::Result<()> {
        self.completed.write_scalar(&(count as i64))
    }

    /// Give every series room for exactly `steps` steps, keeping the first `kept` (see
    /// [`Series::set_steps`]).
    pub fn set_steps(&mut self, raw: &Raw, steps: usize, kept: usize) -> hdf5::Result<()> {
        if let Some(c) = &mut self.checksum {
            // the rewritten dataset keeps what its attribute says it covers
            let covers = read_str(&c.ds, COVERS).ok();
            c.set_steps(raw, steps, kept)?;
            covers.map_or(Ok(()), |v| attr_str(&c.ds, COVERS, &v))?;
        }
        for a in self.normal.iter_mut().flatten().chain(self.rigid.as_mut()) {
            a.set_steps(raw, steps, kept)?;
        }
        self.series(true).into_iter().try_for_each(|s| s.set_steps(raw, steps, kept))
    }

    /// True when the file holds the normal unknowns a resumed run needs ([`super::normal_series`]).
    pub fn has_normal(&self) -> bool {
        self.normal.is_some()
    }

    /// The number of rigid motions whose α the file holds ([`super::rigid_series`]; 0 without).
    pub fn rigid_width(&self) -> usize {
        self.rigid.as_ref().map_or(0, |s| s.ds.shape().get(1).copied().unwrap_or(0))
    }

    /// Overwrite the values of `setup_times` (a file created beside the set-up holds zeros until then).
    pub fn set_setup_times(&self, times: &[f64; 5]) -> hdf5::Result<()> {
        self.group.attr("setup_times")?.write_raw(times)
    }

    /// Record why the run stopped.
    pub fn set_status(&self, status: &str) -> hdf5::Result<()> {
        attr_str(&self.group, "status", status)
    }
}
