"""Signal processing: noise-aware differentiation and continuous wavelets with exact quadrature."""
