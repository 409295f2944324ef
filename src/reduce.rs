//! The laboratory data reduction (physics.md §7). (Being written.)
