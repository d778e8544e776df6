"""Fleet verification: many logs on one machine or a Dask cluster, in constant memory per log,
a fleet report, and live monitoring of a running robot."""
