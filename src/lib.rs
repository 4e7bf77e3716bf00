//! Root package: holds the workspace-level end-to-end and cross-check tests in `tests/`.
