"""Reports: summary.json (numbers), sweep.csv (one row per pose), report.html (plots and tables)."""
