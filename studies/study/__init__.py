"""`parsimony study FILE`: a declared sweep of runs (``schema``) on places of several kinds
(``places``), expanded run by run (``sweep``), each run (``runs``) in a child process of its own
(``execute``) on a local pool (``local``) or a Dask cluster (``cluster``), driven to a results
table that resumes (``drive``, ``results``), and reported as Markdown tables (``report``) with
the figures of ``figures``, and plots (``plots``)."""
