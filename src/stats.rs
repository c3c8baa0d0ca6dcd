//! Run statistics.
