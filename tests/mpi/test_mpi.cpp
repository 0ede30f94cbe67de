// The MPI layer's decisions that need no MPI: which point-to-point layer a run on one
// node asks Open MPI for (mpi::single_node_pml).
#include <gtest/gtest.h>

#include <map>
#include <string>

#include "mpi/mpi.hpp"

namespace {

using superball::mpi::Getenv;
using superball::mpi::single_node_pml;

// An environment holding exactly `vars`.
Getenv environment(const std::map<std::string, std::string>& vars)
{
    return [vars](const char* name) -> const char* {
        const auto it = vars.find(name);
        return it == vars.end() ? nullptr : it->second.c_str();
    };
}

TEST(SingleNodePml, SingletonGetsOb1)
{
    EXPECT_EQ(single_node_pml(environment({{"HOME", "/root"}, {"PATH", "/usr/bin"}}), ""), "ob1");
    // Inside a Slurm allocation but started without srun: still a singleton.
    EXPECT_EQ(single_node_pml(environment({{"SLURM_JOB_ID", "12"}, {"SLURM_NNODES", "4"}}), ""), "ob1");
}

TEST(SingleNodePml, MpirunOnOneNodeGetsOb1)
{
    EXPECT_EQ(single_node_pml(environment({{"OMPI_COMM_WORLD_SIZE", "2"}, {"OMPI_COMM_WORLD_LOCAL_SIZE", "2"},
                                           {"PMIX_RANK", "1"}}),
                              ""),
              "ob1");
}

TEST(SingleNodePml, SeveralNodesKeepOpenMpisChoice)
{
    EXPECT_EQ(single_node_pml(environment({{"OMPI_COMM_WORLD_SIZE", "64"}, {"OMPI_COMM_WORLD_LOCAL_SIZE", "32"},
                                           {"PMIX_RANK", "3"}}),
                              ""),
              "");
    EXPECT_EQ(single_node_pml(environment({{"OMPI_COMM_WORLD_SIZE", "64"}}), ""), "");
}

TEST(SingleNodePml, OtherLaunchersKeepOpenMpisChoice)
{
    // srun (PMIx or PMI-2) and MPICH's hydra say nothing here about the number of nodes.
    for (const char* var : {"PMIX_RANK", "PMI_RANK", "PMI_SIZE", "PMI_FD"}) {
        EXPECT_EQ(single_node_pml(environment({{var, "0"}}), ""), "") << var;
    }
}

TEST(SingleNodePml, TheUsersChoiceIsNeverReplaced)
{
    for (const char* value : {"ucx", "cm", "^ucx", ""}) {
        EXPECT_EQ(single_node_pml(environment({{"OMPI_MCA_pml", value}}), ""), "") << value;
        EXPECT_EQ(single_node_pml(environment({{"OMPI_MCA_pml", value}, {"OMPI_COMM_WORLD_SIZE", "2"},
                                               {"OMPI_COMM_WORLD_LOCAL_SIZE", "2"}}),
                                  ""),
                  "")
            << value;
    }
    EXPECT_EQ(single_node_pml(environment({{"OMPI_MCA_mca_base_param_files", "/etc/site.conf"}}), ""), "");
    // ~/.openmpi/mca-params.conf
    EXPECT_EQ(single_node_pml(environment({}), "# site defaults\nbtl = self,vader,tcp\n  pml\t= ucx  # fast\n"), "");
    EXPECT_EQ(single_node_pml(environment({}), "btl = self,vader\n# pml = ucx\npml_ucx_verbose = 1\n"), "ob1");
}

}  // namespace
