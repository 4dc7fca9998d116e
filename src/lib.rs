//! covtrace
