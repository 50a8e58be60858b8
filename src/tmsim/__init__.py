"""TMflow robot simulator (docs/simulator.md): ``protocol`` (codecs and sans-I/O sessions), ``tmscript`` (the
script language), ``robot`` (the robot model and what hangs on it), ``net`` (server and TCP adapters), ``limits``
(every bound) and ``cli`` (the command line ``tmflow-sim``)."""
