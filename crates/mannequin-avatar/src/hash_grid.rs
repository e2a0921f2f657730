//! Multi-resolution hash encoding (instant-ngp).
