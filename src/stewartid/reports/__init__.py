"""Reports render results: tables, figures, the HTML page, method labels, terminal tables,
matrix exports and the identification report. Nothing here fits a model."""
