//! The direct formulation: a QP on the CL C values through the analysis spline.
