//! Statistical and closed-form tests of the lights.
