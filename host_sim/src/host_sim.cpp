namespace fissure::host {}  // the host_sim issue fills this module
