"""`renderer batch`: a job file's items (scenes x cameras x sweep points x settings) rendered
once each, written atomically with a manifest (JSONL) that makes a re-run resume; on Ray's
workers or in this process (renderer/cluster)."""
