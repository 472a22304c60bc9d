"""The pipeline: registration stages, deviations, sections, reports, batches."""
