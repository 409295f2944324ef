//! Built-in set-ups.
