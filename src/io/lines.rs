//! Line numbers of byte offsets in a model file, for messages: the line starts are found once and
//! each lookup is a binary search (roxmltree's `text_pos_at` scans from the start of the text each
//! time, which made loading quadratic in file size). Shared by the URDF and MJCF readers.

/// The start of every line of a text.
pub(crate) struct LineIndex {
    starts: Vec<usize>,
}

impl LineIndex {
    pub(crate) fn new(text: &str) -> Self {
        let starts = std::iter::once(0).chain(text.match_indices('\n').map(|(i, _)| i + 1)).collect();
        LineIndex { starts }
    }

    /// The 1-based line of byte offset `pos`.
    pub(crate) fn line(&self, pos: usize) -> u32 {
        u32::try_from(self.starts.partition_point(|&s| s <= pos)).unwrap_or(u32::MAX)
    }
}
