"""What a sweep's results say: metrics, the report and its plots."""
