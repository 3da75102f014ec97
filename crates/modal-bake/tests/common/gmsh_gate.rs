//! The gate of the tests that run the real gmsh: they skip with a message when it is missing,
//! unless `DCR_REQUIRE_GMSH=1` (set by `.ci/run`), where they fail.

/// Whether gmsh can run; `false` (skip) only when `DCR_REQUIRE_GMSH` is not `1`.
pub fn have_gmsh(test: &str) -> bool {
    match modal_bake::mesh::gmsh::gmsh_version(None) {
        Ok(_) => true,
        Err(e) => {
            if std::env::var("DCR_REQUIRE_GMSH").as_deref() == Ok("1") {
                panic!("{test}: DCR_REQUIRE_GMSH=1 but {e}");
            }
            eprintln!("SKIPPED {test}: {e}");
            false
        }
    }
}
