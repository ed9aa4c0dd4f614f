"""The verification harness of tresca-cr: the requirements declared once (:mod:`.requirements`), the harness
that records results and writes reports (:mod:`.harness`), the reader of the CLI's ``--json`` summaries
(:mod:`.summary`), the README table generated from the requirements (:mod:`.readme`) and the studies of
``make verify`` (:mod:`.studies`, :mod:`.estimates`, :mod:`.stability`, :mod:`.planner`)."""
