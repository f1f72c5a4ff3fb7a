//! Options shared by every command that reads a test log (column mapping, units, gaps).
