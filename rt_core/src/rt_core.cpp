namespace fissure::rt {}  // the rt_core issue fills this module
