//! The campaign results database (SQLite).
