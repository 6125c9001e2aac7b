"""Speed measurements: each reports ratios against a baseline measured in the same run."""
