//! Size before work (`--max-memory`, `--max-time`, `--force`): the estimate of
//! [`modal_bake::bake::SizeEstimate`] printed before meshing and baking, and a refusal with the
//! estimate and how to lower it when it is over the budget; a transfer table's build is held to
//! the same budget once its modes are known ([`modal_bake::transfer::TablePlan`]).

use std::path::Path;

use clap::Args;
use modal_bake::bake::{self as mb, Budget, SizeEstimate, SurfaceMeasures};
use modal_bake::transfer::TransferModes;

use super::mesh::AssetOptions;

/// The surface asset at `path` as `mesh` reads it: `--object` only, scaled to m by `--units`.
///
/// # Errors
/// The reader's, naming the file.
pub fn read_in_metres(
    path: &Path,
    asset: &AssetOptions,
) -> anyhow::Result<modal_bake::mesh::surface::SurfaceMesh> {
    let mut s = modal_bake::mesh::surface::read_surface_object(path, asset.object.as_deref())?;
    let to_m = asset.units.to_metres();
    if to_m != 1.0 {
        s.scale(to_m);
    }
    Ok(s)
}

/// The budget of one `mesh` or `bake` run.
#[derive(Args, Clone, Debug)]
pub struct BudgetOptions {
    /// Refuse (before any long work) when the estimated peak memory of meshing or baking is
    /// above this (GB, 1e9 bytes); a transfer table's build (--transfer-h) is held to it too,
    /// checked once the table's modes are known.
    #[arg(long, value_name = "GB", default_value_t = 2.0)]
    pub max_memory: f64,
    /// Refuse (before any long work) when the estimated wall time of meshing plus baking is
    /// above this (seconds); a transfer table's build (--transfer-h) is held to it too,
    /// checked once the table's modes are known.
    #[arg(long, value_name = "SECONDS", default_value_t = 300.0)]
    pub max_time: f64,
    /// Run even when an estimate is over --max-memory or --max-time.
    #[arg(long)]
    pub force: bool,
}

impl BudgetOptions {
    /// The budget in SI units.
    ///
    /// # Errors
    /// A non-positive or non-finite `--max-memory` or `--max-time`.
    pub fn budget(&self) -> anyhow::Result<Budget> {
        Budget::from_gb(
            self.max_memory,
            self.max_time,
            ["--max-memory", "--max-time"],
        )
        .map_err(anyhow::Error::msg)
    }

    /// The budget a transfer table's build is held to ([`TransferParams::budget`]): `None`
    /// with `--force`.
    ///
    /// [`TransferParams::budget`]: modal_bake::transfer::TransferParams::budget
    ///
    /// # Errors
    /// As [`BudgetOptions::budget`].
    pub fn table_budget(&self) -> anyhow::Result<Option<Budget>> {
        let b = self.budget()?;
        Ok((!self.force).then_some(b))
    }

    /// `error` with the way round a refused table build (`--max-memory`, `--max-time`,
    /// `--force`) when it is one; unchanged otherwise.
    pub fn explain_table_refusal(&self, error: mb::BakeError) -> anyhow::Error {
        if error.is_table_over_budget() {
            anyhow::anyhow!(
                "{error}; or raise --max-memory / --max-time, or pass --force to build it anyway"
            )
        } else {
            anyhow::Error::new(error)
        }
    }

    fn describe(&self) -> String {
        format!(
            "the budget of {} GB and {} (--max-memory, --max-time)",
            self.max_memory,
            mb::format_seconds(self.max_time)
        )
    }

    /// Estimates meshing the surface asset `path` with `asset` and baking `modes` modes of the
    /// mesh (`mesh` too: the mesh is made to be baked) and a transfer table's mode set `table`,
    /// prints the estimate (stderr) and refuses it over the budget unless `--force`.
    /// The refusal names the estimate, the budget and the smallest coarsening of `--size` that
    /// fits.
    ///
    /// # Errors
    /// An unreadable surface (the reader's message), or the estimate over the budget.
    pub fn check_surface(
        &self,
        path: &Path,
        asset: &AssetOptions,
        modes: usize,
        table: Option<TransferModes>,
    ) -> anyhow::Result<SizeEstimate> {
        // The reader's errors name the file.
        let s = read_in_metres(path, asset)?;
        self.check_read_surface(path, &s, asset, modes, table)
    }

    /// [`BudgetOptions::check_surface`] of the surface `s` already read from `path` (in m:
    /// `--object` and `--units` applied, as [`read_in_metres`] does).
    ///
    /// # Errors
    /// The estimate over the budget.
    pub fn check_read_surface(
        &self,
        path: &Path,
        s: &modal_bake::mesh::surface::SurfaceMesh,
        asset: &AssetOptions,
        modes: usize,
        table: Option<TransferModes>,
    ) -> anyhow::Result<SizeEstimate> {
        let budget = self.budget()?;
        let measures = SurfaceMeasures::of(&s.vertices, &s.triangles);
        let size = asset
            .size
            .unwrap_or_else(|| modal_bake::mesh::gmsh::default_size(s.bounding_box()));
        let order = asset.order();
        // gmsh's curvature-driven sizes put more elements on a curved surface than `size`
        // alone: estimate at the equivalent uniform size.
        let curvature = !asset.uniform_size && !asset.keep_surface;
        let thickness = !asset.no_thickness_sizing && !asset.keep_surface;
        // fTetWild (forced, or auto on a surface that does not bound one solid as it is)
        // makes more elements than gmsh at the same size.
        let ftetwild = match asset.mesher {
            super::mesh::MesherArg::Ftetwild => true,
            super::mesh::MesherArg::Gmsh => false,
            super::mesh::MesherArg::Auto => {
                !modal_bake::mesh::surface::inspect_surface(s).is_solid()
            }
        };
        // `k`: the fraction of the estimate's elements the mesh is taken to have (1: the
        // estimate; below 1: the fewest the mesher has made against it).
        let est_k = |size: f64, order: u8, k: f64| {
            let h = modal_bake::mesh::sizing::equivalent_size(s, size, curvature, thickness);
            let e = SizeEstimate::of_surface(&measures, h, asset.keep_surface, order, modes);
            let e = if ftetwild { e.for_ftetwild() } else { e }.with_elements(k);
            match table {
                Some(t) => e.with_table_modes(t, e.dofs as usize),
                None => e,
            }
        };
        let est = |size: f64, order: u8| est_k(size, order, 1.0);
        let fits = |e: &SizeEstimate| e.fits(&budget);
        let e = est(size, order);
        eprintln!(
            "size estimate for {} ({} triangles, {:.4e} m³, size {:.4e} m{}): {}",
            path.display(),
            mb::format_count(measures.triangles as f64),
            measures.volume_m3,
            size,
            if asset.keep_surface {
                format!(
                    ", --keep-surface: its {:.4e} m triangles set the size",
                    measures.mean_edge()
                )
            } else if ftetwild {
                format!(
                    ", fTetWild: about {} times gmsh's elements",
                    modal_bake::bake::FTETWILD_ELEMENTS
                )
            } else if curvature || thickness {
                format!(
                    ", finer where {}: as many elements as a uniform {:.4e} m",
                    match (curvature, thickness) {
                        (true, true) => "curved or thin",
                        (true, false) => "curved",
                        _ => "thin",
                    },
                    modal_bake::mesh::sizing::equivalent_size(s, size, curvature, thickness)
                )
            } else {
                String::new()
            },
            e.describe()
        );
        if fits(&e) {
            return Ok(e);
        }
        // The element count is known only once meshed: when the fewest elements the mesher has
        // made against this estimate would fit (and meshing itself does), mesh first and let
        // the bake be decided on the mesh's exact counts (`check_mesh`, or `mesh`'s warning).
        // With --keep-surface the asset's own triangles set the count: no such uncertainty.
        let fewest = modal_bake::bake::FEWEST_ELEMENTS[usize::from(ftetwild)];
        let meshing = SizeEstimate {
            bake_s: 0.0,
            bake_bytes: 0.0,
            table_modes_s: 0.0,
            table_modes_bytes: 0.0,
            ..e
        };
        if !self.force && !asset.keep_surface && fits(&meshing) && fits(&est_k(size, order, fewest))
        {
            eprintln!(
                "note: {}: the estimate is over {}, but its element count is uncertain before meshing ({} has made as few as {:.2} times it, which would fit): meshing first; the bake is checked on the mesh's exact counts",
                path.display(),
                self.describe(),
                if ftetwild { "fTetWild" } else { "gmsh" },
                fewest
            );
            return Ok(e);
        }
        let mut how = Vec::new();
        if asset.keep_surface {
            how.push(format!(
                "drop --keep-surface (its {} triangles, {:.4e} m apart, set the tetrahedra; remeshing at --size {:.4e} gives {})",
                mb::format_count(measures.triangles as f64),
                measures.mean_edge(),
                size,
                SizeEstimate::of_surface(
                    &measures,
                    modal_bake::mesh::sizing::equivalent_size(
                        s,
                        size,
                        !asset.uniform_size,
                        !asset.no_thickness_sizing
                    ),
                    false,
                    order,
                    modes
                )
                .describe()
            ));
            how.push(
                "decimate the asset in the modelling tool (Blender: Decimate modifier)".into(),
            );
        } else if let Some(fit) = (1..=40)
            .map(|k| size * 1.2f64.powi(k))
            .find(|&h| fits(&est(h, order)))
        {
            how.push(format!(
                "a coarser --size {fit:.3e} m ({})",
                est(fit, order).describe()
            ));
        }
        if order == 2 && fits(&est(size, 1)) {
            how.push(format!(
                "--order 1 ({}; linear tetrahedra are much less accurate in bending)",
                est(size, 1).describe()
            ));
        }
        how.push("fewer --modes".into());
        let file = path.display().to_string();
        self.refuse(&file, "meshing or baking", &e, &how, measures.extent_m)
    }

    /// Estimates baking `mesh` with `params` ([`SizeEstimate::of_bake`]: its modes and a
    /// transfer table's mode set), prints it when it is long (stderr) and refuses it over the
    /// budget unless `--force`.
    ///
    /// # Errors
    /// The estimate over the budget.
    pub fn check_mesh(
        &self,
        file: &str,
        mesh: &modal_bake::mesh::TetMesh,
        params: &mb::BakeParams,
    ) -> anyhow::Result<SizeEstimate> {
        let budget = self.budget()?;
        let e = SizeEstimate::of_bake(mesh, params);
        if e.total_s() >= 10.0 || !e.fits(&budget) {
            eprintln!("size estimate for baking {file}: {}", e.describe());
        }
        if e.fits(&budget) {
            return Ok(e);
        }
        let mut how = vec![
            "a coarser mesh (a larger --size when meshing; halving the tetrahedra more than halves the time)".to_string(),
            "fewer --modes".to_string(),
        ];
        if e.table_modes_s > 0.0 {
            how.push(
                "fewer --transfer-modes (a count the base's --modes cover needs no second solve)"
                    .into(),
            );
        }
        self.refuse(file, "baking", &e, &how, mesh.extent())
    }

    /// After `mesh`: the bake of `mesh` (20 modes, `bake`'s default) estimated on its exact
    /// counts, printed with a warning when it is over the budget (`bake` would refuse it).
    ///
    /// # Errors
    /// A malformed budget.
    pub fn warn_bake(&self, file: &str, mesh: &modal_bake::mesh::TetMesh) -> anyhow::Result<()> {
        let budget = self.budget()?;
        let e = SizeEstimate::of_bake(mesh, &mb::BakeParams::default());
        if !e.fits(&budget) {
            eprintln!(
                "warning: {file}: baking it (20 modes) is estimated on its counts at {}: over {}; `modal-bake bake` will refuse it: mesh again with a coarser --size (or --order 1), or give bake a larger --max-memory / --max-time",
                e.describe(),
                self.describe()
            );
        }
        Ok(())
    }

    /// Refuses `e` (unless `--force`) before the work `before` names ("meshing or baking",
    /// "baking").
    fn refuse(
        &self,
        file: &str,
        before: &str,
        e: &SizeEstimate,
        how: &[String],
        extent_m: f64,
    ) -> anyhow::Result<SizeEstimate> {
        if self.force {
            eprintln!(
                "warning: {file}: the estimate is over {}; running anyway (--force)",
                self.describe()
            );
            return Ok(*e);
        }
        let scale = mb::unit_hint(extent_m).map_or_else(String::new, |h| format!("; note: {h}"));
        anyhow::bail!(
            "{file}: refused before {before}: estimated {} is over {}; to lower it: {}; or pass --force to run anyway{scale}",
            e.describe(),
            self.describe(),
            how.join(", or ")
        )
    }
}
