//! Smooth padding of the free pixels of geometry images (filled in by the padding issue).
