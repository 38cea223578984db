//! The watertight ray/triangle test (in progress).
