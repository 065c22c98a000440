"""Benchmark sweeps: spec files (:mod:`.spec`) expanded into cells, run by an executor
(:mod:`.executors`) through :mod:`.runner` into a resumable cell store (:mod:`.store`), then the
long table and summaries (:mod:`.tables`), plots (:mod:`.plots`), the HTML report (:mod:`.report`)
and regression checks against a baseline (:mod:`.compare`)."""
