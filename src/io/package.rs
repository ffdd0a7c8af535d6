//! package:// resolution
