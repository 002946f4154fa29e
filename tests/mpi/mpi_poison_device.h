/* SPDX-License-Identifier: MIT */
/* A sticky device error on demand for gpu_check_mpi_device_lost (mpi_poison_device.cu). */
#ifndef SPH_TESTS_MPI_POISON_DEVICE_H
#define SPH_TESTS_MPI_POISON_DEVICE_H

#ifdef __cplusplus
extern "C" {
#endif

/* A CUDA event of the current device (cudaEvent_t), NULL if it could not be made. */
void* mpi_device_event_create(void);
/* Poisons this process's CUDA context; nonzero when the device reported the fault. */
int mpi_poison_device(void);

#ifdef __cplusplus
}
#endif

#endif /* SPH_TESTS_MPI_POISON_DEVICE_H */
