//! Mesh export (filled in below).
