//! The names methods report their phase timings and model statistics under
//! ([`crate::DeformationMethod::phase_timings`], [`crate::DeformationMethod::model_statistics`]):
//! one constant per name, used by the methods and by the harness's reports alike.

/// Phase timing keys (seconds), grouped by the method that reports them.
pub mod phase {
    // isolines (Au et al. 2007) and hirm.
    pub const PRECOMPUTE_LAPLACIAN: &str = "precompute_laplacian";
    pub const BIND_HARMONIC_FIELDS: &str = "bind_harmonic_fields";
    pub const BIND_ISOLINES: &str = "bind_isolines";
    pub const BIND_REDUCED_SYSTEM: &str = "bind_reduced_system";
    pub const SOLVE_CONSTRAINT_RHS: &str = "solve_constraint_rhs";
    pub const SOLVE_VERTEX_POSITIONS: &str = "solve_vertex_positions";
    /// Prefix of the per-solve phases, replaced by every solve.
    pub const SOLVE_PREFIX: &str = "solve_";

    // hirm (Wu et al. 2015, Table 1's names).
    /// `t_e`: the propagation fields (eigenvectors of the rest mesh).
    pub const T_E_PROPAGATION_FIELDS: &str = "t_e_propagation_fields";
    /// `t_b`: the handle-independent system, in the background after each solve.
    pub const T_B_BACKGROUND_PRECOMPUTE: &str = "t_b_background_precompute";
    /// `t_h`: the handle update (eq 26 and its factorization).
    pub const T_H_HANDLE_UPDATE: &str = "t_h_handle_update";
    /// Growing the fields for a handle set with more regions (section 5).
    pub const T_G_FIELD_GROWTH: &str = "t_g_field_growth";
    /// `bind_handles` waiting for a background precompute still running.
    pub const BIND_BACKGROUND_WAIT: &str = "bind_background_wait";

    // spectral_mhb (Rong et al. 2008, pt1-3 precompute, rt1-2 runtime).
    pub const PT1_MANIFOLD_HARMONICS: &str = "pt1_manifold_harmonics";
    pub const PT2_REDUCED_ENERGY: &str = "pt2_reduced_energy";
    pub const PT3_DETAIL_SYSTEM: &str = "pt3_detail_system";
    pub const RT1_CONSTRAINT_RHS: &str = "rt1_constraint_rhs";
    pub const RT1_REDUCED_SOLVE: &str = "rt1_reduced_solve";
    pub const RT2_INVERSE_MHT: &str = "rt2_inverse_mht";
    pub const RT2_DETAILS: &str = "rt2_details";

    // scale_aware (Liu et al. 2014).
    pub const INITIALIZATION_LAPLACIAN: &str = "initialization_laplacian";
    pub const STEP_ONE_NORMALS: &str = "step_one_normals";
    pub const STEP_TWO_ASSEMBLY: &str = "step_two_assembly";
    pub const STEP_TWO_REFACTORIZATION: &str = "step_two_refactorization";
    pub const STEP_TWO_BACK_SUBSTITUTION: &str = "step_two_back_substitution";
    pub const ORA_STITCHING: &str = "ora_stitching";
}

/// Model statistic keys (counts).
pub mod statistic {
    /// Isolines of an isoline model (`isolines`).
    pub const N_ISOLINES: &str = "n_isolines";
    /// Sampled crossed triangles (`isolines`: `n_tri`).
    pub const N_TRI: &str = "n_tri";
    /// hirm's propagation fields, isolines per field and sampled crossed triangles (Table 1).
    pub const N_FIELD: &str = "n_field";
    pub const N_ISO: &str = "n_iso";
    pub const N_T: &str = "n_t";
    /// scale_aware's outer iterations and Gauss-map (normal) iterations.
    pub const OUTER_ITERATIONS: &str = "outer_iterations";
    pub const NORMAL_ITERATIONS: &str = "normal_iterations";
    /// scale_aware's step two: numeric factorizations, lagged steps with a held one, and the
    /// back-substitutions of those (conjugate gradients preconditioned by the held factor).
    pub const REFACTORIZATIONS: &str = "refactorizations";
    pub const LAGGED_STEPS: &str = "lagged_steps";
    pub const LAGGED_BACK_SUBSTITUTIONS: &str = "lagged_back_substitutions";
    /// arap's saddle test: the relative energies of the first answer and of the perturbed solve's,
    /// and whether the latter is the result (1) or not (0).
    pub const SADDLE_TEST_FIRST_ENERGY: &str = "saddle_test_first_energy";
    pub const SADDLE_TEST_SECOND_ENERGY: &str = "saddle_test_second_energy";
    pub const SADDLE_TEST_SECOND_KEPT: &str = "saddle_test_second_kept";
}

/// The registered method names, the one place they are spelled (re-exported by
/// [`crate::registry`], whose table registers them; the harness's reports and tables use them).
pub mod method_name {
    pub const LAPLACIAN: &str = "laplacian";
    pub const ARAP: &str = "arap";
    pub const HIRM: &str = "hirm";
    pub const SPECTRAL_MHB: &str = "spectral_mhb";
    pub const SCALE_AWARE: &str = "scale_aware";
    pub const SCALE_AWARE_ORA: &str = "scale_aware_ora";
    pub const ISOLINES: &str = "isolines";
    pub const ISOLINES_T1: &str = "isolines_t1";
}
