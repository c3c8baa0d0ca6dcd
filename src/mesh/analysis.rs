//! Mesh analysis (filled in below).
