//! fenestra-contrib: the contribution tracer behind rtcontrib/rcontrib and the Klems window sampler behind genklemsamp (being written).
